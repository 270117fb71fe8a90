#pragma once
// The room's light at the character, from the map's posed keyframes (issue 14, item 1).
//
// Each keyframe pixel is radiance arriving at the scene point it sees. Its ray is cast into
// the scene proxy (room/scene_proxy.h: planes fitted to the map's points); the point hit is
// then seen from the character's position, so the pixel's value goes to the direction from the
// character to that point. Rays that miss the proxy are taken as distant (the camera ray's own
// direction). The samples are averaged in an equirectangular map of directions (64 x 32);
// directions no keyframe saw take the value of their nearest seen neighbours; the map is
// projected onto order-2 spherical harmonics (9 RGB coefficients), and a dominant directional
// light is taken out of them (room/sh.h).
//
// Assumptions, stated: the camera is linear (pixel value / 255 is radiance, no gamma, no
// saturation: clipped pixels under-read bright lights); the scene is Lambertian (a point sends
// the same radiance to the camera and to the character); the light is static; the proxy is
// right where the map has points and missing elsewhere.
//
// At run time the live camera changes its exposure and white balance: ExposureFollower
// compares the live frame with the keyframe that looked most nearly the same way (both
// reduced to 40 x 30 thumbnails, saturated pixels left out) and scales the light by the ratio,
// per channel, smoothed over frames.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "base/error.h"
#include "calib/camera.h"
#include "calib/pose.h"
#include "room/ray_caster.h"
#include "room/sh.h"

namespace arview::room {

struct LightError : Error {
  using Error::Error;
};

struct LightKeyframe {
  calib::Camera camera;  // with its distortion
  calib::Pose pose;      // world → camera
  cv::Mat image;         // 8-bit BGR, or CV_32FC3 linear BGR (synthetic HDR keyframes)
};

struct KeyframeThumbnail {
  calib::Pose pose;
  cv::Mat linear_bgr;  // CV_32FC3, 40 x 30
  // The keyframe camera (pinhole part: fx, fy, cx, cy) and image size, to project into it.
  Eigen::Vector4d intrinsics = Eigen::Vector4d::Zero();
  cv::Size image_size;
};

struct RoomLight {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // where the light was measured (map frame)
  ShRgb sh{};                                          // incident radiance, RGB
  DominantLight dominant;
  double seen_fraction = 0;  // share of the sphere of directions some keyframe pixel saw
  int keyframes = 0;
  double seconds = 0;        // estimation time
  std::vector<KeyframeThumbnail> thumbnails;
  std::vector<Eigen::Vector3f> scene_triangles;     // the proxy the light was measured through (map frame)
  std::vector<Eigen::Vector3f> occluder_triangles;  // depth-only occluders (map frame): the proxy without the floor
};

struct LightEstimateOptions {
  int environment_width = 64;  // equirectangular map of directions, width x width/2
  int sample_width = 160;      // keyframes are reduced to this width (area average) before sampling
  int thumbnail_width = 40;
};

// Throws LightError when there are no keyframes or an image is unusable.
RoomLight EstimateRoomLight(std::span<const LightKeyframe> keyframes, const TriangleBvh& scene,
                            const Eigen::Vector3d& position, const LightEstimateOptions& options = {});

// The thumbnail ExposureFollower compares: area-averaged, linear (8-bit / 255), BGR float.
// Thumbnail pixels over a clipped camera pixel (any channel ≥ kClippedLevel) are set to
// kClippedThumbnail in every channel and left out of the comparison.
inline constexpr int kClippedLevel = 250;
inline constexpr float kClippedThumbnail = 1.0f;
cv::Mat LinearThumbnail(const cv::Mat& image, int width);

// YAML (OpenCV FileStorage), written atomically; Load throws LightError naming the file.
void SaveRoomLight(const RoomLight& light, const std::filesystem::path& file);
RoomLight LoadRoomLight(const std::filesystem::path& file);

class ExposureFollower {
 public:
  // `smoothing` in (0, 1]: the share of the new ratio taken each frame (in log units).
  // `scene_triangles`: the proxy; with it each live thumbnail pixel is compared with what the
  // chosen keyframe saw of the same scene point (its ray cast into the proxy, the point
  // projected into the keyframe, seen unoccluded), so a live view between keyframes and the
  // pixels left out as clipped compare like with like. Without it, pixel with pixel.
  // `live_camera`: the live camera (its pinhole part is used).
  ExposureFollower(std::vector<KeyframeThumbnail> thumbnails, const std::vector<Eigen::Vector3f>& scene_triangles,
                   const calib::Camera& live_camera, double smoothing = 0.25);
  // The live frame (8-bit BGR or grey, raw camera image) and its pose; returns the smoothed
  // per-channel gain (RGB) to apply to the stored light. Without thumbnails the gain stays 1.
  Eigen::Vector3d Update(const cv::Mat& live, const calib::Pose& pose);
  Eigen::Vector3d gain() const { return gain_; }
  // The keyframe the last Update compared with (−1 before any).
  int last_keyframe() const { return last_keyframe_; }

 private:
  // Σ live and Σ keyframe over the comparable thumbnail pixels (RGB); false when too few.
  bool Compare(const cv::Mat& live_thumbnail, const calib::Pose& pose, const KeyframeThumbnail& key,
               Eigen::Vector3d* live_sum, Eigen::Vector3d* key_sum) const;
  std::vector<KeyframeThumbnail> thumbnails_;
  std::unique_ptr<TriangleBvh> scene_;
  calib::Camera live_camera_;
  double smoothing_;
  double centre_spread_ = 1;
  Eigen::Vector3d gain_ = Eigen::Vector3d::Ones();
  bool started_ = false;
  int last_keyframe_ = -1;
};

}  // namespace arview::room
