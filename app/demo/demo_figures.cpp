#include "app/demo/demo_figures.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "anim_authoring/lookat.h"
#include "anim/pose.h"
#include "base/stats.h"
#include "video/sinks.h"

namespace arview::app {

CharacterMarkers MarkersOf(const anim::Character& character, const Eigen::Matrix4d& model_to_world) {
  const anim::Skeleton& sk = character.skeleton;
  const anim::LocalPose rest = anim::LocalPose::Rest(sk);
  std::vector<Eigen::Matrix4d> model(sk.size());
  anim::MustRun(anim::LocalToModelJob{&sk, &rest, model}, "character markers");
  auto world = [&](const Eigen::Vector3d& p) { return Eigen::Vector3d((model_to_world * p.homogeneous()).head<3>()); };

  CharacterMarkers m;
  for (const auto& joint : model) m.joints.push_back(world(joint.block<3, 1>(0, 3)));
  const std::vector<std::string> chain = authoring::DefaultLookAtChain(sk);
  int head = chain.empty() ? -1 : sk.Find(chain.back());
  if (head < 0) {
    head = 0;
    for (int j = 1; j < sk.size(); ++j)
      if (model[j](1, 3) > model[head](1, 3)) head = j;
  }
  m.head = m.joints[head];
  m.root = m.joints.empty() ? world(Eigen::Vector3d::Zero()) : m.joints[0];
  Eigen::AlignedBox3d box;
  for (const anim::Mesh& mesh : character.meshes)
    for (const Eigen::Vector3f& p : mesh.positions) box.extend(p.cast<double>());
  if (box.isEmpty())
    for (const auto& joint : model) box.extend(Eigen::Vector3d(joint.block<3, 1>(0, 3)));
  for (int corner = 0; corner < 8; ++corner) m.extent.push_back(world(box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner))));
  return m;
}

InViewSummary MeasureInView(const calib::Camera& camera, const std::vector<std::optional<calib::Pose>>& poses,
                            const CharacterMarkers& markers) {
  InViewSummary s;
  s.frames = poses.size();
  std::vector<double> in_view_heights;
  for (const auto& pose : poses) {
    bool visible = false;
    double fraction = 0;
    if (pose) {
      auto seen = [&](const Eigen::Vector3d& world) {
        const Eigen::Vector3d c = pose->ToCamera(world);
        return c.z() > 0.05 && camera.InImage(camera.Project(c));
      };
      visible = seen(markers.head) && seen(markers.root);
      // The vertical extent of the skin's box in the picture, clipped to it; points behind the
      // camera are left out (the box is then partly out of view anyway).
      double top = std::numeric_limits<double>::infinity(), bottom = -top;
      for (const Eigen::Vector3d& p : markers.extent) {
        const Eigen::Vector3d c = pose->ToCamera(p);
        if (c.z() <= 0.05) continue;
        const double v = camera.Project(c).y();
        top = std::min(top, v);
        bottom = std::max(bottom, v);
      }
      if (bottom > top) fraction = (std::clamp(bottom, 0.0, double(camera.height)) - std::clamp(top, 0.0, double(camera.height))) / camera.height;
    }
    s.per_frame.push_back(visible);
    s.height_fraction.push_back(fraction);
    if (visible) {
      ++s.in_view;
      in_view_heights.push_back(fraction);
      if (fraction >= 0.2) ++s.at_least_a_fifth;
    }
  }
  if (!in_view_heights.empty()) {
    s.median_height_fraction = Median(in_view_heights);
    s.min_height_fraction = *std::min_element(in_view_heights.begin(), in_view_heights.end());
  }
  return s;
}

namespace {

// The frames of a sheet of `n` tiles over `frames`: spread evenly, first to last, with `include`
// in the place of the spread frame nearest it.
std::vector<int> SheetFrames(int n, int frames, std::optional<int> include) {
  std::vector<int> picked;
  for (int i = 0; i < n; ++i) picked.push_back(n == 1 ? 0 : static_cast<int>(std::lround(double(i) * (frames - 1) / (n - 1))));
  if (include && *include >= 0 && *include < frames) {
    const auto nearest = std::min_element(picked.begin(), picked.end(),
                                          [&](int a, int b) { return std::abs(a - *include) < std::abs(b - *include); });
    *nearest = *include;
  }
  return picked;
}

// Every frame of a video file. Frame counts from container metadata can be approximate: read
// them all, the caller keeps the chosen.
std::vector<cv::Mat> ReadVideoFrames(const std::filesystem::path& video) {
  cv::VideoCapture capture(video.string());
  if (!capture.isOpened()) throw std::runtime_error(video.string() + ": cannot open the video for the contact sheet");
  std::vector<cv::Mat> frames;
  for (cv::Mat frame; capture.read(frame);) frames.push_back(frame.clone());
  return frames;
}

// The frames of a PNG folder as a FrameSink writes it (`--out <folder>`, video/sinks.h), in order
// up to the first index missing.
std::vector<cv::Mat> ReadPngFrames(const std::filesystem::path& folder) {
  std::vector<cv::Mat> frames;
  for (int index = 0;; ++index) {
    const std::filesystem::path file = video::PngFrameFile(folder, index);
    if (!std::filesystem::exists(file)) break;
    cv::Mat frame = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (frame.empty()) throw std::runtime_error(file.string() + ": cannot read the frame for the contact sheet");
    frames.push_back(std::move(frame));
  }
  return frames;
}

}  // namespace

cv::Mat ContactSheet(const std::filesystem::path& video, int count, int columns, int tile_width, std::optional<int> include) {
  const std::vector<cv::Mat> frames = std::filesystem::is_directory(video) ? ReadPngFrames(video) : ReadVideoFrames(video);
  if (frames.empty()) throw std::runtime_error(video.string() + ": no frames to make a contact sheet of");
  const int n = std::min<int>(count, static_cast<int>(frames.size()));
  const int tile_height = tile_width * frames[0].rows / frames[0].cols;
  const int rows = (n + columns - 1) / columns;
  cv::Mat sheet(rows * tile_height, columns * tile_width, CV_8UC3, cv::Scalar::all(0));
  const std::vector<int> picked = SheetFrames(n, static_cast<int>(frames.size()), include);
  for (int i = 0; i < n; ++i) {
    const int index = picked[static_cast<std::size_t>(i)];
    cv::Mat tile;
    cv::resize(frames[index], tile, {tile_width, tile_height}, 0, 0, cv::INTER_AREA);
    const std::string label = "frame " + std::to_string(index);
    cv::putText(tile, label, {8, tile_height - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar::all(0), 3, cv::LINE_AA);
    cv::putText(tile, label, {8, tile_height - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar::all(255), 1, cv::LINE_AA);
    tile.copyTo(sheet(cv::Rect((i % columns) * tile_width, (i / columns) * tile_height, tile_width, tile_height)));
  }
  return sheet;
}

cv::Mat WithCloseUp(const cv::Mat& sheet, const cv::Mat& close_up, int tile_width, int tile_height,
                    const std::vector<std::string>& lines) {
  if (close_up.cols < tile_width || close_up.rows < tile_height || sheet.cols < 2 * tile_width || sheet.type() != CV_8UC3 ||
      close_up.type() != CV_8UC3)
    throw std::invalid_argument("contact sheet: a close-up of " + std::to_string(close_up.cols) + "x" + std::to_string(close_up.rows) +
                                " does not fill a tile of " + std::to_string(tile_width) + "x" + std::to_string(tile_height) +
                                " on a sheet " + std::to_string(sheet.cols) + " wide");
  cv::Mat out(sheet.rows + tile_height, sheet.cols, CV_8UC3, cv::Scalar::all(0));
  sheet.copyTo(out(cv::Rect(0, 0, sheet.cols, sheet.rows)));
  const cv::Rect centre((close_up.cols - tile_width) / 2, (close_up.rows - tile_height) / 2, tile_width, tile_height);
  close_up(centre).copyTo(out(cv::Rect(0, sheet.rows, tile_width, tile_height)));
  for (std::size_t i = 0; i < lines.size(); ++i)
    cv::putText(out, lines[i], {tile_width + 16, sheet.rows + 36 + 28 * static_cast<int>(i)}, cv::FONT_HERSHEY_SIMPLEX, 0.6,
                cv::Scalar::all(255), 1, cv::LINE_AA);
  return out;
}

}  // namespace arview::app
