#include "render/hmd.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "base/input_guard.h"
#include "render/offscreen.h"

namespace arview::render {
namespace {

[[noreturn]] void Fail(const std::filesystem::path& file, const std::string& problem) {
  throw RenderError(file.string() + ": HMD profile: " + problem);
}

double Number(const YAML::Node& node, const std::filesystem::path& file, const std::string& field, double lo, double hi) {
  double value = 0;
  try {
    value = node.as<double>();
  } catch (const YAML::Exception&) {
    Fail(file, field + " is not a number");
  }
  if (!std::isfinite(value) || value < lo || value > hi) {
    Fail(file, field + " is " + std::to_string(value) + ", outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return value;
}

// A two-number list such as `panel: [2560, 1440]`.
Eigen::Vector2d Pair(const YAML::Node& root, const std::filesystem::path& file, const std::string& field, double lo,
                     double hi) {
  const YAML::Node node = root[field];
  if (!node || !node.IsSequence() || node.size() != 2) Fail(file, field + " must be a list of two numbers");
  return {Number(node[0], file, field + "[0]", lo, hi), Number(node[1], file, field + "[1]", lo, hi)};
}

}  // namespace

HmdProfile LoadHmdProfile(const std::filesystem::path& file) {
  const std::string text = ReadFileUpTo(file, kMaxCameraFileBytes);
  RequireYamlDepthAtMost(text, 8, file.string());
  if (const auto duplicate = FindDuplicateYamlKey(text)) Fail(file, "key '" + duplicate->key + "' appears twice (lines " + std::to_string(duplicate->first_line) + " and " + std::to_string(duplicate->line) + ")");
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    Fail(file, "not YAML (" + std::string(e.what()) + ")");
  }
  if (!root.IsMap()) Fail(file, "expected a mapping with panel, eye_fov_deg, lens_centre and distortion");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (key != "name" && key != "panel" && key != "eye_fov_deg" && key != "lens_centre" && key != "distortion") {
      Fail(file, "unknown key '" + PrintableForMessage(key) + "' (expected name, panel, eye_fov_deg, lens_centre, distortion)");
    }
  }
  HmdProfile p;
  p.name = root["name"] ? root["name"].as<std::string>() : file.stem().string();
  const Eigen::Vector2d panel = Pair(root, file, "panel", 2, 16384);
  if (panel.x() != std::floor(panel.x()) || panel.y() != std::floor(panel.y())) Fail(file, "panel must be whole pixels");
  if (static_cast<int>(panel.x()) % 2 != 0) Fail(file, "panel width must be even (two halves, one per eye)");
  p.panel = {static_cast<int>(panel.x()), static_cast<int>(panel.y())};
  if (!root["eye_fov_deg"]) Fail(file, "eye_fov_deg is missing");
  p.eye_fov_deg = Number(root["eye_fov_deg"], file, "eye_fov_deg", 10, 170);
  p.lens_centre = root["lens_centre"] ? Pair(root, file, "lens_centre", 0, 1) : Eigen::Vector2d(0.5, 0.5);
  if (root["distortion"]) {
    const Eigen::Vector2d k = Pair(root, file, "distortion", -1, 10);
    p.k1 = k.x(), p.k2 = k.y();
  }
  return p;
}

HmdPresenter::HmdPresenter(const HmdProfile& profile, const calib::Camera& view) : profile_(profile), view_(view) {
  const cv::Size half(profile_.panel.width / 2, profile_.panel.height);
  if (half.width <= 0 || half.height <= 0) throw RenderError("HMD profile " + profile_.name + ": empty panel");
  // The eye's half spans eye_fov_deg across its width: its focal length in panel pixels.
  eye_focal_px_ = 0.5 * half.width / std::tan(0.5 * profile_.eye_fov_deg * M_PI / 180.0);
  for (int eye = 0; eye < 2; ++eye) {
    map_x_[eye].create(half, CV_32FC1);
    map_y_[eye].create(half, CV_32FC1);
    for (int y = 0; y < half.height; ++y) {
      float* mx = map_x_[eye].ptr<float>(y);
      float* my = map_y_[eye].ptr<float>(y);
      for (int x = 0; x < half.width; ++x) {
        const Eigen::Vector2d source = SourceOf(eye, {x, y});
        mx[x] = static_cast<float>(source.x());
        my[x] = static_cast<float>(source.y());
      }
    }
  }
}

Eigen::Vector2d HmdPresenter::LensCentre(int eye) const {
  const double half_width = profile_.panel.width / 2.0;
  const double x = eye == 0 ? profile_.lens_centre.x() : 1.0 - profile_.lens_centre.x();
  return {x * half_width, profile_.lens_centre.y() * profile_.panel.height};
}

Eigen::Vector2d HmdPresenter::SourceOf(int eye, const Eigen::Vector2d& panel_px) const {
  // The panel point's direction as the lens shows it: its tangent-plane position from the lens
  // centre, magnified by the lens's radial polynomial. The view is sampled in that direction.
  const Eigen::Vector2d u = (panel_px - LensCentre(eye)) / eye_focal_px_;
  const double r2 = u.squaredNorm();
  const Eigen::Vector2d seen = u * (1 + profile_.k1 * r2 + profile_.k2 * r2 * r2);
  return {view_.cx + view_.fx * seen.x(), view_.cy + view_.fy * seen.y()};
}

cv::Mat HmdPresenter::Present(const cv::Mat& left, const cv::Mat& right) const {
  cv::Mat panel(profile_.panel, CV_8UC3, cv::Scalar::all(0));
  const int half = profile_.panel.width / 2;
  const cv::Mat* views[2] = {&left, &right};
  for (int eye = 0; eye < 2; ++eye) {
    cv::Mat target = panel(cv::Rect(eye * half, 0, half, profile_.panel.height));
    cv::remap(*views[eye], target, map_x_[eye], map_y_[eye], cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  }
  return panel;
}

}  // namespace arview::render
