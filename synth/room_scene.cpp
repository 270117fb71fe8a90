// The room of synth_room.h, apart from the recording written of it (synth_room.cpp): its scene
// (walls, floor and ceiling with opencv-doc's photos, the boxes, the window of the window light,
// the floor board), its geometry for ground truth (RoomWindow, RoomRayDepth, the board's
// corners), the cameras, the hand-held path and the renderer of one frame. The lights
// (room_lights.cpp), the venue (synth_venue.cpp), tests and tools use them too.

#include "synth/synth_room.h"

#include "base/image_file.h"

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <map>
#include <cmath>
#include <random>
#include <string_view>

#include "render/projection.h"
#include "synth/recording_folder.h"
#include "synth/room_size.h"

namespace arview::synth {
namespace {

namespace fs = std::filesystem;

// Trilinear mipmaps plus 4x anisotropic filtering: oblique walls and floor stay sharp (more
// features) without aliasing; 16x costs llvmpipe ~20% more per frame for little visible gain.
constexpr float kRoomAnisotropy = 4.f;
// Panels stand this far in front of the paint they hang on, so depth never fights.
constexpr double kPanelOffset = 0.004;

struct Wall {
  Eigen::Vector3d facing;  // viewing direction of someone looking at the wall from inside
  double distance;         // from the room's vertical axis
  double length;
  Eigen::Vector3f shade;
  std::vector<const char*> images;
};

// Photos chosen for dense, distinct texture (many SIFT features, no repeated patterns, no two
// views of the same scene), so that every part of the room is recognisable.
const std::array<Wall, 4>& Walls() {
  static const std::array<Wall, 4> walls = {{
      {{0, 1, 0}, kHalfY, 2 * kHalfX, {0.95f, 0.95f, 0.93f}, {"building.jpg", "graf1.png", "home.jpg", "leuvenA.jpg"}},
      {{0, -1, 0}, kHalfY, 2 * kHalfX, {0.85f, 0.85f, 0.84f}, {"aero1.jpg", "fruits.jpg", "baboon.jpg", "messi5.jpg"}},
      {{1, 0, 0}, kHalfX, 2 * kHalfY, {0.9f, 0.9f, 0.88f}, {"box_in_scene.png", "rubberwhale1.png", "starry_night.jpg"}},
      {{-1, 0, 0}, kHalfX, 2 * kHalfY, {0.8f, 0.8f, 0.8f}, {"squirrel_cls.jpg", "smarties.png", "left.jpg"}},
  }};
  return walls;
}

const char* kFloorImages[4] = {"aloeL.jpg", "board.jpg", "licenseplate_motion.jpg", "text_defocus.jpg"};
const char* kCeilingImages[2] = {"Blender_Suzanne1.jpg", "sudoku.png"};

struct BoxSpec {
  Eigen::Vector2d center;
  double yaw;
  Eigen::Vector3d size;
  std::array<const char*, 5> images;  // four sides, then the top
};

const std::array<BoxSpec, 3>& Boxes() {
  static const std::array<BoxSpec, 3> boxes = {{
      {{2.1, 1.3}, 0.35, {0.8, 0.8, 0.9},
       {"basketball1.png", "ela_original.jpg", "butterfly.jpg", "pca_test1.jpg", "orange.jpg"}},
      {{-2.3, -1.1}, -0.25, {1.0, 0.6, 0.6},
       {"blox.jpg", "chicky_512.png", "HappyFish.jpg", "cards.png", "apple.jpg"}},
      {{0.9, -1.8}, 0.7, {0.6, 0.6, 1.2},
       {"stuff.jpg", "imageTextN.png", "detect_blob.png", "text_motion.jpg", "LinuxLogo.jpg"}},
  }};
  return boxes;
}

// Resamples a photo to power-of-two sides (nearest in log scale). With odd sizes down the mip
// chain, Mesa's mipmap generation shifts levels by up to half a texel, which would move
// texture content by a few tenths of a pixel against the exact geometry.
cv::Mat PowerOfTwo(const cv::Mat& image) {
  auto side = [](int n) { return 1 << std::clamp(static_cast<int>(std::lround(std::log2(n))), 6, 11); };
  cv::Mat out;
  cv::resize(image, out, {side(image.cols), side(image.rows)}, 0, 0, cv::INTER_AREA);
  return out;
}

class SceneBuilder {
 public:
  explicit SceneBuilder(const fs::path& data_dir) : data_dir_(data_dir) {
    scene_.textures.push_back(cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(255)));
    paint_.texture = 0;
  }

  // A rectangle centred at `center` spanned by unit `right` and `up`.
  void Panel(const char* image, const Eigen::Vector3d& center, const Eigen::Vector3d& right,
             const Eigen::Vector3d& up, double width, double height, const Eigen::Vector3f& shade) {
    RoomPanel panel{image, {}, Texture(image)};
    SetPanelCorners(panel, center, right, up, width, height);
    render::TriangleBatch batch;
    batch.texture = panel.texture;
    render::AppendQuad(batch, panel.corners, Eigen::Vector4f(0, 0, 1, 1), shade);
    scene_.batches.push_back(std::move(batch));
    scene_.panels.push_back(std::move(panel));
  }

  void Paint(const Eigen::Vector3d corners[4], const Eigen::Vector3f& colour) {
    render::AppendQuad(paint_, corners, Eigen::Vector4f(0, 0, 1, 1), colour);
  }

  // A rectangle with a texture made here rather than read from a photo (the board).
  void GeneratedPanel(const std::string& name, const cv::Mat& texture, const Eigen::Vector3d& center,
                      const Eigen::Vector3d& right, const Eigen::Vector3d& up, double width, double height,
                      const Eigen::Vector3f& shade) {
    scene_.textures.push_back(texture);
    loaded_[name] = static_cast<int>(scene_.textures.size()) - 1;
    Panel(name.c_str(), center, right, up, width, height, shade);
  }

  double Aspect(const char* image) {
    Texture(image);
    return aspect_.at(image);
  }

  RoomScene Finish() {
    scene_.batches.push_back(std::move(paint_));
    return std::move(scene_);
  }

 private:
  int Texture(const char* name) {
    if (auto it = loaded_.find(name); it != loaded_.end()) return it->second;
    const fs::path path = data_dir_ / name;
    cv::Mat image;
    try {
      image = ReadImageFile(path, cv::IMREAD_COLOR);  // a cut or damaged photo: one line naming it
    } catch (const Error& e) {
      throw render::RenderError(std::string(e.what()) + " (the room's photos come from Debian package opencv-doc)");
    }
    aspect_[name] = static_cast<double>(image.cols) / image.rows;
    scene_.textures.push_back(PowerOfTwo(image));
    return loaded_[name] = static_cast<int>(scene_.textures.size()) - 1;
  }

  fs::path data_dir_;
  RoomScene scene_;
  render::TriangleBatch paint_;
  std::map<std::string, int> loaded_;
  std::map<std::string, double> aspect_;
};

// The window of SynthLighting::kWindow takes this photo's place on its wall.
constexpr const char* kWindowReplaces = "graf1.png";

constexpr double kWindowWidth = 1.4, kWindowHeight = 1.6, kWindowCentreZ = 1.7, kWindowBar = 0.06;
// The transom lies this share of the half-height above the window's centre.
constexpr double kTransomAt = 0.25;

// A window seen from inside: panes clipped white by the daylight behind them, in a dark frame
// with a mullion and a transom (their corners give the tracker something to hold on to).
void AddWindow(SceneBuilder& builder, const Eigen::Vector3d& center, const Eigen::Vector3d& right,
               const Eigen::Vector3d& up, const Eigen::Vector3d& inward, double width, double height) {
  auto rectangle = [&](const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double offset, const Eigen::Vector3f& colour) {
    const Eigen::Vector3d o = center + inward * offset;
    const Eigen::Vector3d corners[4] = {o + right * lo.x() + up * hi.y(), o + right * hi.x() + up * hi.y(),
                                        o + right * hi.x() + up * lo.y(), o + right * lo.x() + up * lo.y()};
    builder.Paint(corners, colour);
  };
  const double w = width / 2, h = height / 2, bar = kWindowBar;
  const Eigen::Vector3f pane(1.f, 1.f, 1.f), frame(0.3f, 0.27f, 0.24f);
  rectangle({-w, -h}, {w, h}, kPanelOffset, pane);
  const double in_front = 2 * kPanelOffset;
  rectangle({-w, -h}, {-w + bar, h}, in_front, frame);
  rectangle({w - bar, -h}, {w, h}, in_front, frame);
  rectangle({-w, h - bar}, {w, h}, in_front, frame);
  rectangle({-w, -h}, {w, -h + bar}, in_front, frame);
  rectangle({-bar / 2, -h}, {bar / 2, h}, in_front, frame);              // mullion
  rectangle({-w, kTransomAt * h - bar / 2}, {w, kTransomAt * h + bar / 2}, in_front, frame);  // transom
}

void AddWalls(SceneBuilder& builder, SynthLighting light) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  for (const Wall& wall : Walls()) {
    const Eigen::Vector3d right = wall.facing.cross(up);
    const Eigen::Vector3d base = wall.facing * wall.distance;
    const Eigen::Vector3d paint[4] = {base - right * wall.length / 2 + up * kHeight,
                                      base + right * wall.length / 2 + up * kHeight,
                                      base + right * wall.length / 2, base - right * wall.length / 2};
    builder.Paint(paint, wall.shade.cwiseProduct(Eigen::Vector3f(0.86f, 0.83f, 0.78f)));
    const int n = static_cast<int>(wall.images.size());
    const double spacing = wall.length / n;
    for (int i = 0; i < n; ++i) {
      const double along = -wall.length / 2 + spacing * (i + 0.5);
      if (light == SynthLighting::kWindow && std::string_view(wall.images[i]) == kWindowReplaces) {
        AddWindow(builder, base + right * along + up * kWindowCentreZ, right, up, -wall.facing, kWindowWidth, kWindowHeight);
        continue;
      }
      const double height = 1.6;
      const double width = std::min(height * builder.Aspect(wall.images[i]), spacing - 0.2);
      const Eigen::Vector3d center = base - wall.facing * kPanelOffset + right * along + up * 1.4;
      builder.Panel(wall.images[i], center, right, up, width, height, wall.shade);
    }
  }
}

void AddFloorAndCeiling(SceneBuilder& builder, SynthLighting light) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d floor[4] = {{-kHalfX, kHalfY, 0}, {kHalfX, kHalfY, 0}, {kHalfX, -kHalfY, 0}, {-kHalfX, -kHalfY, 0}};
  // Under a window the floor is the dark side of the room (the light comes from the side and
  // above); evenly lit, it is as bright as the walls.
  const float floor_light = light == SynthLighting::kWindow ? 0.6f : 1.f;
  builder.Paint(floor, Eigen::Vector3f(0.55f, 0.5f, 0.45f) * floor_light);
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d center((i % 2 ? 0.5 : -0.5) * kHalfX, (i / 2 ? 0.5 : -0.5) * kHalfY, kPanelOffset);
    builder.Panel(kFloorImages[i], center, x, y, kHalfX - 0.1, kHalfY - 0.1, Eigen::Vector3f::Constant(0.9f * floor_light));
  }
  Eigen::Vector3d ceiling[4];
  for (int i = 0; i < 4; ++i) ceiling[i] = floor[i] + Eigen::Vector3d(0, 0, kHeight);
  builder.Paint(ceiling, {0.7f, 0.7f, 0.7f});
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d center((i ? 0.5 : -0.5) * kHalfX, 0, kHeight - kPanelOffset);
    builder.Panel(kCeilingImages[i], center, x, -y, kHalfX - 0.3, 2 * kHalfY - 0.6, {0.75f, 0.75f, 0.75f});
  }
}

// The board's picture: (columns + 1) x (rows + 1) squares, black in the top-left corner, in a
// white margin one square wide. Drawn 16 times larger and averaged down, so that a square's edge
// that falls inside a texel shades it by the covered share (an exact edge position on average).
cv::Mat BoardTexture(const FloorBoard& board) {
  const int columns = board.inner_corners.width + 3, rows = board.inner_corners.height + 3;  // squares with margin
  constexpr int kSide = 1024, kOversample = 16;
  cv::Mat fine(kSide * kOversample / 2, kSide * kOversample / 2, CV_8UC3, cv::Scalar::all(255));
  for (int y = 0; y < fine.rows; ++y) {
    const int row = y * rows / fine.rows;
    for (int x = 0; x < fine.cols; ++x) {
      const int column = x * columns / fine.cols;
      const bool inside = row > 0 && row < rows - 1 && column > 0 && column < columns - 1;
      if (inside && (row + column) % 2 == 0) fine.at<cv::Vec3b>(y, x) = cv::Vec3b(20, 20, 20);
    }
  }
  cv::Mat texture;
  cv::resize(fine, texture, {kSide, kSide}, 0, 0, cv::INTER_AREA);
  return texture;
}

// Above the floor's photos (which lie kPanelOffset above the paint), facing up.
void AddFloorBoard(SceneBuilder& builder, const FloorBoard& board, SynthLighting light) {
  if (board.empty()) return;
  const Eigen::Vector3d along(std::cos(board.yaw), std::sin(board.yaw), 0);
  const Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(along);
  // The texture's top row is the board's row 0: texture "up" points against the rows' order.
  const Eigen::Vector3d center(board.centre.x(), board.centre.y(), 2 * kPanelOffset);
  const float shade = light == SynthLighting::kWindow ? 0.6f : 0.95f;
  builder.GeneratedPanel("generated chessboard", BoardTexture(board), center, along, -across,
                         (board.inner_corners.width + 3) * board.square, (board.inner_corners.height + 3) * board.square,
                         Eigen::Vector3f::Constant(shade));
}

void AddBoxes(SceneBuilder& builder) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d light = Eigen::Vector3d(0.5, 0.3, 0).normalized();
  for (const BoxSpec& box : Boxes()) {
    const Eigen::Matrix3d r = Eigen::AngleAxisd(box.yaw, up).toRotationMatrix();
    const Eigen::Vector3d center(box.center.x(), box.center.y(), box.size.z() / 2);
    for (int side = 0; side < 4; ++side) {
      // Outward normals +x, +y, −x, −y of the box frame; widths follow.
      const double angle = side * M_PI / 2;
      const Eigen::Vector3d normal = r * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0);
      const double depth = (side % 2 ? box.size.y() : box.size.x()) / 2;
      const double width = side % 2 ? box.size.x() : box.size.y();
      const Eigen::Vector3d right = (-normal).cross(up);
      const float shade = static_cast<float>(0.72 + 0.25 * std::max(0.0, normal.dot(light)));
      builder.Panel(box.images[side], center + normal * depth, right, up, width, box.size.z(),
                    {shade, shade, shade});
    }
    builder.Panel(box.images[4], center + up * box.size.z() / 2, r.col(0), r.col(1), box.size.x(), box.size.y(),
                  {1.f, 1.f, 1.f});
  }
}

// Uniform in [0, 1) from the engine's raw bits: the standard distributions are not specified
// bit-exactly across standard libraries, and the path must be the same everywhere for a seed.
double Unit(std::mt19937_64& engine) { return static_cast<double>(engine() >> 11) * 0x1.0p-53; }

double SmootherStep(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * s * (s * (6 * s - 15) + 10);
}

}  // namespace

std::vector<Eigen::Vector3d> FloorBoard::Corners() const {
  const Eigen::Vector3d along(std::cos(yaw), std::sin(yaw), 0);
  const Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(along);
  const Eigen::Vector3d first = Eigen::Vector3d(centre.x(), centre.y(), 2 * kPanelOffset) -
                                along * square * (inner_corners.width - 1) / 2 + across * square * (inner_corners.height - 1) / 2;
  std::vector<Eigen::Vector3d> corners;
  for (int row = 0; row < inner_corners.height; ++row)
    for (int column = 0; column < inner_corners.width; ++column)
      corners.push_back(first + along * square * column - across * square * row);
  return corners;
}

RoomScene MakeRoomScene(const fs::path& data_dir, SynthLighting light, const FloorBoard& board) {
  SceneBuilder builder(data_dir);
  AddWalls(builder, light);
  AddFloorAndCeiling(builder, light);
  AddFloorBoard(builder, board, light);
  AddBoxes(builder);
  return builder.Finish();
}

WindowGeometry RoomWindow() {
  for (const Wall& wall : Walls()) {
    for (size_t i = 0; i < wall.images.size(); ++i) {
      if (std::string_view(wall.images[i]) != kWindowReplaces) continue;
      const double spacing = wall.length / static_cast<double>(wall.images.size());
      const double along = -wall.length / 2 + spacing * (static_cast<double>(i) + 0.5);
      const Eigen::Vector3d right = wall.facing.cross(Eigen::Vector3d::UnitZ());
      const double x = (wall.facing * wall.distance + right * along).x();
      return {wall.distance, x - kWindowWidth / 2, x + kWindowWidth / 2, kWindowCentreZ - kWindowHeight / 2,
              kWindowCentreZ + kWindowHeight / 2, kWindowBar, kWindowCentreZ + kTransomAt * kWindowHeight / 2};
    }
  }
  throw render::RenderError("synth room: internal error: no wall holds the window");
}

double RoomRayDepth(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d lo(-kHalfX, -kHalfY, 0), hi(kHalfX, kHalfY, kHeight);
  if ((origin.array() < lo.array()).any() || (origin.array() > hi.array()).any()) return INFINITY;
  double nearest = INFINITY;
  for (int axis = 0; axis < 3; ++axis) {  // leaving the room's box
    if (direction[axis] > 1e-12) nearest = std::min(nearest, (hi[axis] - origin[axis]) / direction[axis]);
    if (direction[axis] < -1e-12) nearest = std::min(nearest, (lo[axis] - origin[axis]) / direction[axis]);
  }
  for (const BoxSpec& box : Boxes()) {  // entering a box: slabs in the box's frame
    const Eigen::Matrix3d to_box = Eigen::AngleAxisd(-box.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d o = to_box * (origin - Eigen::Vector3d(box.center.x(), box.center.y(), box.size.z() / 2));
    const Eigen::Vector3d d = to_box * direction;
    double enter = 0, leave = INFINITY;
    for (int axis = 0; axis < 3 && enter <= leave; ++axis) {
      const double half = box.size[axis] / 2;
      if (std::abs(d[axis]) < 1e-12) {
        if (std::abs(o[axis]) > half) leave = -1;
        continue;
      }
      const double a = (-half - o[axis]) / d[axis], b = (half - o[axis]) / d[axis];
      enter = std::max(enter, std::min(a, b));
      leave = std::min(leave, std::max(a, b));
    }
    if (enter <= leave && enter > 0) nearest = std::min(nearest, enter);
  }
  return nearest;
}

calib::Camera RoomCamera(int width, int height) {
  const double s = width / 640.0;
  // The 640x480 camera's principal point offset from the image centre, scaled (pixel centres:
  // the image centre is at (W − 1) / 2).
  const double cx = (width - 1) / 2.0 + (321.5 - 319.5) * s;
  const double cy = (height - 1) / 2.0 + (238.5 - 239.5) * s;
  return calib::Camera::Pinhole(width, height, 525.0 * s, 525.0 * s, cx, cy);
}

calib::Camera SynthCamera(const SynthRoomOptions& o) {
  calib::Camera camera = RoomCamera(o.width, o.height);
  camera.fx *= o.focal_scale;
  camera.fy *= o.focal_scale;
  for (int i = 0; i < 5; ++i) camera.dist[i] = o.distortion[i];
  return camera;
}

DistortedRoom::DistortedRoom(const calib::Camera& lens) {
  // The rays of the frame's border bound the pinhole picture (a lens whose distortion is monotonic
  // out from the centre bends no inner ray beyond them).
  double left = 0, right = 0, top = 0, bottom = 0;
  const auto widen = [&](double u, double v) {
    const Eigen::Vector2d n = lens.PixelToNormalized({u, v});
    left = std::min(left, n.x());
    right = std::max(right, n.x());
    top = std::min(top, n.y());
    bottom = std::max(bottom, n.y());
  };
  for (int u = 0; u < lens.width; ++u) {
    widen(u, -0.5);
    widen(u, lens.height - 0.5);
  }
  for (int v = 0; v < lens.height; ++v) {
    widen(-0.5, v);
    widen(lens.width - 0.5, v);
  }
  const double span_x = lens.fx * (right - left), span_y = lens.fy * (bottom - top);
  if (!(span_x <= 3.0 * lens.width - 4 && span_y <= 3.0 * lens.height - 4)) {  // NaN too: no lens
    throw render::RenderError("synth room: the distortion bends the frame's edge rays too far (a pinhole picture more "
                              "than 3 times " + std::to_string(lens.width) + "x" + std::to_string(lens.height) +
                              " would be needed to hold them)");
  }
  const int width = static_cast<int>(std::ceil(span_x)) + 4, height = static_cast<int>(std::ceil(span_y)) + 4;
  pinhole_ = calib::Camera::Pinhole(width, height, lens.fx, lens.fy, 2 - lens.fx * left, 2 - lens.fy * top);
  map_x_.create(lens.height, lens.width, CV_32F);
  map_y_.create(lens.height, lens.width, CV_32F);
  for (int v = 0; v < lens.height; ++v) {
    for (int u = 0; u < lens.width; ++u) {
      const Eigen::Vector2d p = pinhole_.NormalizedToPixel(lens.PixelToNormalized({u, v}));
      map_x_.at<float>(v, u) = static_cast<float>(p.x());
      map_y_.at<float>(v, u) = static_cast<float>(p.y());
    }
  }
}

cv::Mat DistortedRoom::Distort(const cv::Mat& pinhole_picture) const {
  cv::Mat out;
  cv::remap(pinhole_picture, out, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

RoomPath::RoomPath(double duration, uint64_t seed) : duration_(duration) {
  std::mt19937_64 engine(seed);
  angle0_ = 2 * M_PI * Unit(engine);
  direction_ = Unit(engine) < 0.5 ? -1.0 : 1.0;
  pan_phase_ = 2 * M_PI * Unit(engine);
  pitch_phase_ = 2 * M_PI * Unit(engine);
  roll_phase_ = 2 * M_PI * Unit(engine);
  bob_phase_ = 2 * M_PI * Unit(engine);
  turn_sign_ = Unit(engine) < 0.5 ? -1.0 : 1.0;
  for (double& phase : shake_phase_) phase = 2 * M_PI * Unit(engine);
}

calib::Pose RoomPath::At(double t) const {
  constexpr double kTwoPi = 2 * M_PI;
  // Walk: an ellipse round the room's centre at about 0.2 m/s, clear of the boxes, far enough
  // from the walls that the floor in front of them is in view.
  const double angle = angle0_ + direction_ * kTwoPi * 0.045 * t;
  auto shake = [&](int i, double amplitude) {
    return amplitude * (std::sin(kTwoPi * 6.1 * t + shake_phase_[i]) + 0.6 * std::sin(kTwoPi * 9.7 * t + shake_phase_[5 - i]));
  };
  Eigen::Vector3d center(0.9 * std::cos(angle), 0.55 * std::sin(angle), 1.5);
  center.z() += 0.015 * std::sin(kTwoPi * 1.7 * t + bob_phase_);  // steps
  center += Eigen::Vector3d(shake(3, 0.0015), shake(4, 0.0015), shake(5, 0.0015));

  // Look outwards at the walls, panning; one fast 90° turn that the path then keeps.
  const double turn_start = 0.55 * duration_;
  const double turn = turn_sign_ * (M_PI / 2) * SmootherStep((t - turn_start) / 0.6);
  const double yaw = angle + 0.45 * std::sin(kTwoPi * t / 6.5 + pan_phase_) + turn + shake(0, 0.002);
  const double pitch = -0.28 + 0.06 * std::sin(kTwoPi * t / 5.3 + pitch_phase_) + shake(1, 0.002);
  const double roll = 0.03 * std::sin(kTwoPi * t / 4.1 + roll_phase_) + shake(2, 0.0015);

  return HandHeldCameraPose(center, yaw, pitch, roll);
}

RoomRenderer::RoomRenderer(render::OffscreenContext& context, const RoomScene& scene, const calib::Camera& camera, int samples)
    : context_(&context),
      camera_(camera),
      scene_(context.gl(), scene.textures, scene.batches, render::TextureOptions{true, kRoomAnisotropy, false}),
      target_(context.gl(), camera.width, camera.height, samples) {}

RoomRenderer::~RoomRenderer() = default;

void RoomRenderer::SetWalkers(const WalkersOptions& walkers) {
  walkers_ = walkers.count > 0 ? std::make_unique<WalkersRenderer>(context_->gl(), walkers) : nullptr;
}

cv::Mat RoomRenderer::Render(const calib::Pose& pose) { return Render(pose, -INFINITY); }

cv::Mat RoomRenderer::Render(const calib::Pose& pose, double t) {
  const render::GlApi& gl = context_->gl();
  target_.Bind();
  gl.ClearColor(0, 0, 0, 1);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const Eigen::Matrix4d projection = render::ProjectionMatrix(camera_, {0.05, 20.0}), view = render::ViewMatrix(pose);
  scene_.Draw(projection, view);
  if (walkers_ && std::isfinite(t)) walkers_->Draw(projection, view, t);
  return target_.ReadBgr();
}

}  // namespace arview::synth
