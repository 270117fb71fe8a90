// Registration: what the renderer draws lands where OpenCV projects it.

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "render/projection.h"
#include "render/test_scene.h"

namespace arview::render {
namespace {

calib::Camera OddCamera() {
  // Off-centre principal point and unequal focal lengths so that a swapped or mis-signed
  // term shows up.
  return calib::Camera::Pinhole(640, 480, 531.7, 522.3, 331.4, 228.9);
}

calib::Pose SomePose() {
  const Eigen::Quaterniond q_wc = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ());
  return calib::Pose::FromCameraToWorld(q_wc, Eigen::Vector3d(0.4, -0.3, -2.5));
}

cv::Point2d OpenCvProjection(const calib::Camera& camera, const calib::Pose& pose, const Eigen::Vector3d& X) {
  cv::Mat R(3, 3, CV_64F), rvec;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.at<double>(r, c) = pose.R()(r, c);
  cv::Rodrigues(R, rvec);
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << pose.t_cw.x(), pose.t_cw.y(), pose.t_cw.z());
  std::vector<cv::Point2d> out;
  cv::projectPoints(std::vector<cv::Point3d>{{X.x(), X.y(), X.z()}}, rvec, tvec, camera.K(), camera.DistCoeffs(), out);
  return out[0];
}

TEST(Projection, MatchesOpenCvPixelConventionAnalytically) {
  const calib::Camera camera = OddCamera();
  const calib::Pose pose = SomePose();
  const Eigen::Matrix4d mvp = ProjectionMatrix(camera) * ViewMatrix(pose);
  for (const Eigen::Vector3d& X : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, 0.2, 0.1), Eigen::Vector3d(-0.5, 0.4, -0.3)}) {
    const Eigen::Vector4d clip = mvp * X.homogeneous();
    const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
    // Viewport transform, then OpenCV's pixel centres and row order.
    const double u = (ndc.x() + 1) / 2 * camera.width - 0.5;
    const double v = (1 - ndc.y()) / 2 * camera.height - 0.5;
    const cv::Point2d expected = OpenCvProjection(camera, pose, X);
    EXPECT_NEAR(u, expected.x, 1e-9);
    EXPECT_NEAR(v, expected.y, 1e-9);
    EXPECT_GT(ndc.z(), -1);
    EXPECT_LT(ndc.z(), 1);
  }
}

TEST(Projection, RejectsUnusableCamera) {
  calib::Camera camera = OddCamera();
  camera.fx = 0;
  EXPECT_THROW(ProjectionMatrix(camera), RenderError);
  EXPECT_THROW(ProjectionMatrix(OddCamera(), {1.0, 0.5}), RenderError);
}

// Renders small discs at known points and finds their intensity centroids in the read-back.
TEST(Registration, RenderedMarkersLandOnOpenCvProjections) {
  OffscreenContext& context = testing::SharedContext();
  const GlApi& gl = context.gl();
  const calib::Camera camera = OddCamera();
  const calib::Pose pose = SomePose();
  // Points spread over the image at varied depths, found by back-projecting a pixel grid.
  std::vector<Eigen::Vector3d> points;
  for (double u : {60.3, 190.0, 330.7, 470.2, 590.9})
    for (double v : {50.6, 180.1, 300.4, 430.8}) {
      const double depth = 1.5 + 0.002 * u + 0.001 * v;
      const Eigen::Vector3d in_camera(depth * (u - camera.cx) / camera.fx, depth * (v - camera.cy) / camera.fy, depth);
      points.push_back(pose.q_cw.conjugate() * (in_camera - pose.t_cw));
    }
  std::vector<TriangleBatch> batches;
  const Eigen::Vector3d eye = pose.Center();
  for (const auto& p : points) batches.push_back(testing::Disc(p, 0.008, eye, {1, 1, 1}));
  TexturedScene scene(gl, {testing::WhiteTexture()}, batches);
  RenderTarget target(gl, camera.width, camera.height, 4);
  target.Bind();
  gl.ClearColor(0, 0, 0, 1);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  scene.Draw(ProjectionMatrix(camera), ViewMatrix(pose));
  cv::Mat grey;
  cv::cvtColor(target.ReadBgr(), grey, cv::COLOR_BGR2GRAY);

  double worst = 0, sum_dx = 0, sum_dy = 0;
  for (const auto& p : points) {
    const cv::Point2d expected = OpenCvProjection(camera, pose, p);
    const cv::Rect window(cvRound(expected.x) - 8, cvRound(expected.y) - 8, 17, 17);
    ASSERT_TRUE((window & cv::Rect(0, 0, grey.cols, grey.rows)) == window);
    const cv::Moments m = cv::moments(grey(window));
    ASSERT_GT(m.m00, 0) << "marker at " << p.transpose() << " not drawn";
    const cv::Point2d found(window.x + m.m10 / m.m00, window.y + m.m01 / m.m00);
    const cv::Point2d d = found - expected;
    worst = std::max(worst, std::hypot(d.x, d.y));
    sum_dx += d.x;
    sum_dy += d.y;
    EXPECT_LT(std::hypot(d.x, d.y), 0.5) << "marker " << p.transpose();
  }
  // A half-pixel convention slip would be a systematic shift: the mean must be far below it.
  EXPECT_LT(std::abs(sum_dx / points.size()), 0.1);
  EXPECT_LT(std::abs(sum_dy / points.size()), 0.1);
  RecordProperty("worst_marker_error_px", std::to_string(worst));
  std::printf("marker centroids: worst %.3f px, mean (%.3f, %.3f) px\n", worst, sum_dx / points.size(),
              sum_dy / points.size());
}

// Golden image with tolerance: a box's silhouette against its analytic projection.
TEST(Registration, BoxSilhouetteMatchesAnalyticProjection) {
  OffscreenContext& context = testing::SharedContext();
  const GlApi& gl = context.gl();
  const calib::Camera camera = OddCamera();
  const calib::Pose pose = SomePose();
  const Eigen::Isometry3d box_to_world =
      Eigen::Translation3d(0.1, 0.05, 0.2) * Eigen::AngleAxisd(0.6, Eigen::Vector3d(1, 2, 0.5).normalized());
  const Eigen::Vector3d lo(-0.3, -0.2, -0.25), hi(0.35, 0.2, 0.25);
  TexturedScene scene(gl, {testing::WhiteTexture()}, {testing::Box(lo, hi, box_to_world, {1, 1, 1})});
  RenderTarget target(gl, camera.width, camera.height, 4);
  target.Bind();
  gl.ClearColor(0, 0, 0, 1);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  scene.Draw(ProjectionMatrix(camera), ViewMatrix(pose));
  cv::Mat grey, rendered;
  cv::cvtColor(target.ReadBgr(), grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, rendered, 127, 255, cv::THRESH_BINARY);

  // The silhouette of a convex solid is the convex hull of its projected corners.
  std::vector<cv::Point> projected;
  constexpr int kShift = 8;
  for (const auto& c : testing::BoxCorners(lo, hi, box_to_world)) {
    const cv::Point2d p = OpenCvProjection(camera, pose, c);
    projected.emplace_back(cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift)));
  }
  std::vector<cv::Point> hull;
  cv::convexHull(projected, hull);
  cv::Mat analytic = cv::Mat::zeros(grey.size(), CV_8U);
  cv::fillConvexPoly(analytic, hull, cv::Scalar(255), cv::LINE_8, kShift);

  const double intersection = cv::countNonZero(rendered & analytic);
  const double uni = cv::countNonZero(rendered | analytic);
  ASSERT_GT(uni, 1000);
  const double iou = intersection / uni;
  std::printf("box silhouette IoU %.4f (%.0f px)\n", iou, uni);
  EXPECT_GE(iou, 0.98);
}

}  // namespace
}  // namespace arview::render
