#pragma once
// OpenGL matrices from the calibrated camera, in OpenCV's pixel convention.
//
// OpenCV: the centre of the top-left pixel is (0, 0); x right, y down, z forward.
// OpenGL: eye space looks down −z with y up; NDC x = −1 is the left edge of the left pixel
// column. So pixel u (OpenCV) maps to NDC x = 2(u + 0.5)/W − 1 and row v to
// NDC y = 1 − 2(v + 0.5)/H. The y/z flip between the two camera frames is done once, in
// ViewMatrix; ProjectionMatrix consumes OpenGL eye coordinates. RenderTarget flips the rows
// on read-back so that row 0 of the returned image is OpenCV's row 0.

#include <Eigen/Core>

#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::render {

struct ClipRange {
  double near_m = 0.05;
  double far_m = 50.0;
};

// The pinhole part of `camera` (distortion is handled by the caller, see docs/render.md).
Eigen::Matrix4d ProjectionMatrix(const calib::Camera& camera, const ClipRange& clip = {});
// World → OpenGL eye: diag(1, −1, −1, 1) · [R | t].
Eigen::Matrix4d ViewMatrix(const calib::Pose& pose);
// The camera pose seen by an eye offset along the camera's own x axis (metres, + is right):
// for side-by-side stereo, the left eye is −ipd/2 and the right +ipd/2.
calib::Pose OffsetEye(const calib::Pose& pose, double x_offset_m);

}  // namespace arview::render
