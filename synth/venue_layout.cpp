#include "synth/venue_layout.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "render/textured_scene.h"
#include "synth/recording_folder.h"
#include "synth/orbit_walk.h"

namespace arview::synth {
namespace {

// Panels stand this far in front of their wall's paint, and each room's paint this far inside
// its own room, so that depth never fights (a shared wall is painted once from each side).
constexpr double kPanelOffset = 0.004, kPaintOffset = 0.002;
constexpr int kTextureSide = 512;

double Unit(std::mt19937_64& engine) { return static_cast<double>(engine() >> 11) * 0x1.0p-53; }

double SmootherStep(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * s * (s * (6 * s - 15) + 10);
}

// A texture of random shapes at every scale from a few pixels to a quarter of its side, on a
// random ground: many distinct SIFT features, none repeated from another seed.
cv::Mat ShapesTexture(uint64_t seed) {
  std::mt19937_64 engine(seed);
  auto colour = [&] { return cv::Scalar(255 * Unit(engine), 255 * Unit(engine), 255 * Unit(engine)); };
  cv::Mat texture(kTextureSide, kTextureSide, CV_8UC3, colour());
  for (int i = 0; i < 700; ++i) {
    // Sizes log-uniform, 3-36 px (the first 40, under the rest, 4 times that): a panel seen from
    // 1 m still fills the frame with corners and blobs, one seen across the venue too.
    const int size = static_cast<int>(3 * std::pow(12.0, Unit(engine)) * (i < 40 ? 4 : 1));
    const cv::Point centre(static_cast<int>(kTextureSide * Unit(engine)), static_cast<int>(kTextureSide * Unit(engine)));
    const cv::Scalar c = colour();
    switch (engine() % 4) {
      case 0: cv::circle(texture, centre, size, c, cv::FILLED, cv::LINE_AA); break;
      case 1: cv::rectangle(texture, centre, centre + cv::Point(size, static_cast<int>(size * (0.3 + Unit(engine)))), c,
                            cv::FILLED, cv::LINE_AA); break;
      case 2: cv::ellipse(texture, centre, {size, std::max(1, size / 3)}, 360 * Unit(engine), 0, 360, c, cv::FILLED,
                          cv::LINE_AA); break;
      default: {
        const cv::Point to = centre + cv::Point(static_cast<int>(size * (2 * Unit(engine) - 1) * 2),
                                                static_cast<int>(size * (2 * Unit(engine) - 1) * 2));
        cv::line(texture, centre, to, c, 1 + static_cast<int>(3 * Unit(engine)), cv::LINE_AA);
      }
    }
  }
  return texture;
}

class VenueBuilder {
 public:
  explicit VenueBuilder(uint64_t seed) : seed_(seed) {
    scene_.textures.push_back(cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(255)));  // paint
  }

  // A rectangle on a wall: `origin` on the floor, `right` along the wall as seen from inside,
  // `inward` towards the room; `along` and `z` its extent.
  void Paint(const Eigen::Vector3d& origin, const Eigen::Vector3d& right, const Eigen::Vector3d& inward,
             Eigen::Vector2d along, Eigen::Vector2d z, const Eigen::Vector3f& shade) {
    const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), o = origin + inward * kPaintOffset;
    const Eigen::Vector3d corners[4] = {o + right * along[0] + up * z[1], o + right * along[1] + up * z[1],
                                        o + right * along[1] + up * z[0], o + right * along[0] + up * z[0]};
    PaintQuad(corners, shade);
  }

  void PaintQuad(const Eigen::Vector3d corners[4], const Eigen::Vector3f& shade) {
    render::AppendQuad(paint_, corners, Eigen::Vector4f(0, 0, 1, 1), shade);
  }

  // A textured rectangle of its own texture, centred at `centre`, spanned by `right` and `up`.
  void Panel(const Eigen::Vector3d& centre, const Eigen::Vector3d& right, const Eigen::Vector3d& up, double width,
             double height, float shade) {
    RoomPanel panel{"shapes seed " + std::to_string(seed_), {}, static_cast<int>(scene_.textures.size())};
    scene_.textures.push_back(ShapesTexture(seed_++));
    SetPanelCorners(panel, centre, right, up, width, height);
    render::TriangleBatch batch;
    batch.texture = panel.texture;
    render::AppendQuad(batch, panel.corners, Eigen::Vector4f(0, 0, 1, 1), Eigen::Vector3f::Constant(shade));
    scene_.batches.push_back(std::move(batch));
    scene_.panels.push_back(std::move(panel));
  }

  RoomScene Finish() {
    scene_.batches.push_back(std::move(paint_));
    return std::move(scene_);
  }

 private:
  uint64_t seed_;
  RoomScene scene_;
  render::TriangleBatch paint_;
};

// One wall of a room seen from inside: its paint (with a doorway cut out when `door`), and its
// panels, two beside the door or evenly spread.
void AddWall(VenueBuilder& builder, const VenueLayout& v, const Eigen::Vector3d& middle, const Eigen::Vector3d& facing,
             double length, bool door, float shade) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), right = facing.cross(up), inward = -facing;
  const Eigen::Vector3f paint = Eigen::Vector3f(0.86f, 0.83f, 0.78f) * shade;
  const double half = length / 2, half_door = v.door_width / 2;
  if (!door) {
    builder.Paint(middle, right, inward, {-half, half}, {0, v.height}, paint);
    const int panels = length > 4.5 ? 2 : 1;
    const double spacing = length / panels;
    for (int i = 0; i < panels; ++i) {
      const double along = -half + spacing * (i + 0.5);
      builder.Panel(middle + inward * kPanelOffset + right * along + up * 1.35, right, up, spacing - 0.4, 1.5, shade);
    }
    return;
  }
  builder.Paint(middle, right, inward, {-half, -half_door}, {0, v.height}, paint);
  builder.Paint(middle, right, inward, {half_door, half}, {0, v.height}, paint);
  builder.Paint(middle, right, inward, {-half_door, half_door}, {v.door_height, v.height}, paint);  // lintel
  const double side = half - half_door;  // the wall beside the door, each side
  for (const double sign : {-1.0, 1.0}) {
    const double along = sign * (half_door + side / 2);
    builder.Panel(middle + inward * kPanelOffset + right * along + up * 1.3, right, up, side - 0.3, 1.4, shade);
  }
}

void AddRoom(VenueBuilder& builder, const VenueLayout& v, int k) {
  const double cx = v.RoomCentreX(k), hx = v.room_length / 2, hy = v.room_width / 2;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  AddWall(builder, v, {cx, hy, 0}, y, v.room_length, false, 0.95f);
  AddWall(builder, v, {cx, -hy, 0}, -y, v.room_length, false, 0.85f);
  AddWall(builder, v, {cx + hx, 0, 0}, x, v.room_width, k + 1 < v.rooms, 0.9f);
  AddWall(builder, v, {cx - hx, 0, 0}, -x, v.room_width, k > 0, 0.8f);
  // The floor in four textured quarters on its paint; the ceiling painted, one panel on it.
  const Eigen::Vector3d floor[4] = {{cx - hx, hy, 0}, {cx + hx, hy, 0}, {cx + hx, -hy, 0}, {cx - hx, -hy, 0}};
  builder.PaintQuad(floor, {0.55f, 0.5f, 0.45f});
  Eigen::Vector3d ceiling[4];
  for (int i = 0; i < 4; ++i) ceiling[i] = floor[i] + Eigen::Vector3d(0, 0, v.height);
  builder.PaintQuad(ceiling, {0.7f, 0.7f, 0.7f});
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d centre(cx + (i % 2 ? 0.5 : -0.5) * hx, (i / 2 ? 0.5 : -0.5) * hy, kPanelOffset);
    builder.Panel(centre, x, y, hx - 0.1, hy - 0.1, 0.9f);
  }
  builder.Panel({cx, 0, v.height - kPanelOffset}, x, -y, v.room_length - 0.8, v.room_width - 0.8, 0.75f);
}

}  // namespace

int VenueLayout::RoomAt(const Eigen::Vector3d& point) const {
  if (std::abs(point.y()) > room_width / 2) return -1;
  const double from_start = point.x() + rooms * room_length / 2;
  if (from_start < 0 || from_start > rooms * room_length) return -1;
  return std::min(rooms - 1, static_cast<int>(from_start / room_length));
}

std::string VenueLayout::RoomName(int room) { return "room-" + std::to_string(room + 1); }

RoomScene MakeVenueScene(const VenueLayout& layout, uint64_t seed) {
  VenueBuilder builder(seed * 1000);
  for (int k = 0; k < layout.rooms; ++k) AddRoom(builder, layout, k);
  return builder.Finish();
}

VenueWalk::VenueWalk(const VenueLayout& layout, double duration)
    : layout_(layout), unit_(duration / (kTurnShare * layout.rooms + kWalkShare * (layout.rooms - 1))) {}

double VenueWalk::DoorTime(int room) const {
  // The walk from room k to k + 1 covers one room's length from 1 m past k's centre; the door's
  // plane lies at the share (L / 2 - 1 m) / L of it, reached where the smootherstep says.
  const double share = (layout_.room_length / 2 - kTurnRadius) / layout_.room_length;
  double lo = 0, hi = 1;
  for (int i = 0; i < 60; ++i) (SmootherStep((lo + hi) / 2) < share ? lo : hi) = (lo + hi) / 2;
  return unit_ * ((kTurnShare + kWalkShare) * room + kTurnShare + kWalkShare * lo);
}

calib::Pose VenueWalk::At(double t) const {
  // Stretch by stretch: turn in room 0, walk to room 1, turn in room 1, ...
  const double share = std::max(0.0, t / unit_);
  int room = 0;
  double s = share;
  while (room < layout_.rooms - 1 && s >= kTurnShare + kWalkShare) {
    s -= kTurnShare + kWalkShare;
    ++room;
  }
  const double cx = layout_.RoomCentreX(room);
  Eigen::Vector3d centre(cx + kTurnRadius, 0, kCameraHeight);
  double yaw = 0;
  if (s < kTurnShare || room == layout_.rooms - 1) {
    const double angle = 2 * M_PI * SmootherStep(s / kTurnShare);
    centre = Eigen::Vector3d(cx + kTurnRadius * std::cos(angle), kTurnRadius * std::sin(angle), kCameraHeight);
    yaw = angle;
  } else {
    centre.x() += layout_.room_length * SmootherStep((s - kTurnShare) / kWalkShare);
  }
  return HandHeldCameraPose(centre, yaw, kPitch, 0.0);
}

}  // namespace arview::synth
