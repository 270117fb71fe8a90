#include "render/projection.h"

#include "render/offscreen.h"

namespace arview::render {

Eigen::Matrix4d ProjectionMatrix(const calib::Camera& camera, const ClipRange& clip) {
  if (camera.width <= 0 || camera.height <= 0 || !(camera.fx > 0) || !(camera.fy > 0)) {
    throw RenderError("camera for rendering needs a positive image size and focal lengths");
  }
  if (!(clip.near_m > 0) || !(clip.far_m > clip.near_m)) {
    throw RenderError("clip range needs 0 < near < far");
  }
  const double w = camera.width, h = camera.height, n = clip.near_m, f = clip.far_m;
  // Derivation: with eye coordinates (xe, ye, ze), x/z = xe/−ze and y/z = ye/ze, so
  // NDC x = (2 fx/W · xe + (2(cx+0.5)/W − 1)·(−ze)) / (−ze), and likewise for y with the sign
  // of the principal-point term reversed because rows grow downwards.
  const double cx_term = 2.0 * (camera.cx + 0.5) / w - 1.0;
  const double cy_term = 1.0 - 2.0 * (camera.cy + 0.5) / h;
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 2.0 * camera.fx / w;
  p(0, 2) = -cx_term;
  p(1, 1) = 2.0 * camera.fy / h;
  p(1, 2) = -cy_term;
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2.0 * f * n / (f - n);
  p(3, 2) = -1.0;
  return p;
}

Eigen::Matrix4d ViewMatrix(const calib::Pose& pose) {
  Eigen::Matrix4d rt = Eigen::Matrix4d::Identity();
  rt.topLeftCorner<3, 3>() = pose.R();
  rt.topRightCorner<3, 1>() = pose.t_cw;
  const Eigen::Vector4d flip(1, -1, -1, 1);
  return flip.asDiagonal() * rt;
}

calib::Pose OffsetEye(const calib::Pose& pose, double x_offset_m) {
  // x_eye = x_cam − (offset, 0, 0): the eye sits at +offset along the camera's x axis.
  calib::Pose eye = pose;
  eye.t_cw -= Eigen::Vector3d(x_offset_m, 0, 0);
  return eye;
}

}  // namespace arview::render
