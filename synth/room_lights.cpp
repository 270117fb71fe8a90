#include "synth/room_lights.h"

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "synth/synth_room.h"

namespace arview::synth {
namespace {

constexpr double kAutoExposureStepEv = 1.0 / 3;
constexpr int kAutoExposureEveryFrames = 4;
constexpr double kAutoExposureDelayS = 0.3;
constexpr double kSunGain = 1.0;  // the patch adds the lamp's full light again: +1 EV

// How much direct sun reaches the surface point p through the window's opening: 1 in the
// patch, 0 outside and under the bars, a 2 cm soft edge (the sun's disc).
double SunThroughWindow(const Eigen::Vector3d& p, const Eigen::Vector3d& to_sun) {
  const WindowGeometry w = RoomWindow();
  if (to_sun.y() <= 1e-6) return 0;
  const double along = (w.wall_y - p.y()) / to_sun.y();
  if (along < 0) return 0;
  const Eigen::Vector3d q = p + along * to_sun;
  auto inside = [](double v, double lo, double hi) {
    constexpr double kEdge = 0.02;
    return std::clamp((v - lo) / kEdge + 0.5, 0.0, 1.0) * std::clamp((hi - v) / kEdge + 0.5, 0.0, 1.0);
  };
  const double open = inside(q.x(), w.x_min + w.bar, w.x_max - w.bar) * inside(q.z(), w.z_min + w.bar, w.z_max - w.bar);
  const double x_mid = (w.x_min + w.x_max) / 2;
  const double mullion = 1 - inside(q.x(), x_mid - w.bar / 2, x_mid + w.bar / 2);
  const double transom = 1 - inside(q.z(), w.transom_z - w.bar / 2, w.transom_z + w.bar / 2);
  return open * mullion * transom;
}

// Toward the sun at time t: 35° above the horizon, its azimuth sweeping from 30° one side of the
// window's normal to 30° the other over the recording.
Eigen::Vector3d ToSun(const LightChanges& changes, double t) {
  const double s = changes.duration_s > 0 ? std::clamp(t / changes.duration_s, 0.0, 1.0) : 0.5;
  const double azimuth = (-30 + 60 * s) * M_PI / 180, elevation = 35 * M_PI / 180;
  return {std::cos(elevation) * std::sin(azimuth), std::cos(elevation) * std::cos(azimuth), std::sin(elevation)};
}

// The sun's share at each pixel, computed at half resolution (the patch's edge is soft).
cv::Mat SunPatch(const calib::Camera& camera, const calib::Pose& pose, const Eigen::Vector3d& to_sun) {
  const int w = (camera.width + 1) / 2, h = (camera.height + 1) / 2;
  cv::Mat half(h, w, CV_32F);
  const Eigen::Matrix3d R_wc = pose.q_cw.conjugate().toRotationMatrix();
  const Eigen::Vector3d centre = pose.Center();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3d ray = (R_wc * camera.Unproject({2.0 * x + 0.5, 2.0 * y + 0.5})).normalized();
      const double depth = RoomRayDepth(centre, ray);
      half.at<float>(y, x) = std::isfinite(depth) ? static_cast<float>(SunThroughWindow(centre + depth * ray, to_sun)) : 0.f;
    }
  }
  cv::Mat full;
  cv::resize(half, full, {camera.width, camera.height}, 0, 0, cv::INTER_LINEAR);
  return full;
}

}  // namespace

double LampGain(const LightChanges& changes, double t) {
  const bool off = changes.lamp_off_s >= 0 && t >= changes.lamp_off_s && !(changes.lamp_on_s >= 0 && t >= changes.lamp_on_s);
  return off ? kLampOffGain : 1.0;
}

double ExposureGain(const LightChanges& changes, double fps, int frame) {
  if (!changes.auto_exposure) return 1.0;
  // The camera meters what it saw kAutoExposureDelayS ago and steps toward making up for it.
  const int delay = static_cast<int>(std::lround(kAutoExposureDelayS * fps));
  double ev = 0;
  for (int k = kAutoExposureEveryFrames; k <= frame; k += kAutoExposureEveryFrames) {
    const double target = -std::log2(LampGain(changes, std::max(0, k - delay) / fps));
    ev += std::clamp(target - ev, -kAutoExposureStepEv, kAutoExposureStepEv);
  }
  return std::exp2(ev);
}

void ApplyLightChanges(cv::Mat& image, const LightChanges& changes, const calib::Camera& camera, const calib::Pose& pose,
                       double fps, int frame, const cv::Mat& walkers) {
  if (!changes.any()) return;
  const double t = frame / fps;
  const double lamp = LampGain(changes, t), exposure = ExposureGain(changes, fps, frame);
  cv::Mat gain(image.size(), CV_32F, cv::Scalar(lamp));
  if (changes.sun) {
    cv::Mat patch = SunPatch(camera, pose, ToSun(changes, t));
    if (!walkers.empty()) patch.setTo(0, walkers);
    gain += kSunGain * patch;
  }
  gain *= exposure;
  cv::Mat lit;
  image.convertTo(lit, CV_32FC3);
  cv::Mat gain3;
  cv::merge(std::vector<cv::Mat>{gain, gain, gain}, gain3);
  lit = lit.mul(gain3);
  lit.convertTo(image, CV_8UC3);  // saturating
}

}  // namespace arview::synth
