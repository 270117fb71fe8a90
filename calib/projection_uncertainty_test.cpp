#include "calib/projection_uncertainty.h"

#include <gtest/gtest.h>

#include <random>

#include <Eigen/Eigenvalues>

#include <opencv2/calib3d.hpp>

namespace arview::calib {
namespace {

const Camera kTruth = [] {
  Camera c = Camera::Pinhole(640, 480, 600, 605, 322, 236);
  c.dist = {-0.2, 0.08, 0.001, -0.0005, 0};
  return c;
}();

struct BoardPose {
  cv::Vec3d rvec, tvec;
};

// A 9x6 board of 25 mm squares, centred on its origin.
std::vector<cv::Point3f> BoardPoints() {
  std::vector<cv::Point3f> points;
  for (int row = 0; row < 6; ++row) {
    for (int column = 0; column < 9; ++column) points.emplace_back((column - 4) * 0.025f, (row - 2.5f) * 0.025f, 0.f);
  }
  return points;
}

// Boards whose centres are seen at the given pixel offsets from the centre (as fractions of the
// half width and height), 0.4-0.6 m away, turned a little about both axes.
std::vector<BoardPose> Poses(double reach) {
  std::vector<BoardPose> poses;
  int k = 0;
  for (double u : {-1.0, 0.0, 1.0}) {
    for (double v : {-1.0, 0.0, 1.0}) {
      const double z = 0.4 + 0.1 * (k % 3);
      const double x = u * reach * 320 / kTruth.fx * z, y = v * reach * 240 / kTruth.fy * z;
      poses.push_back({cv::Vec3d(0.3 * ((k % 2) ? 1 : -1), 0.25 * (k % 3 - 1), 0.05), cv::Vec3d(x, y, z)});
      ++k;
    }
  }
  return poses;
}

std::vector<BoardDetection> Observe(const std::vector<BoardPose>& poses, double noise_px, std::mt19937& random) {
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<BoardDetection> views;
  for (const BoardPose& pose : poses) {
    BoardDetection view;
    view.object_points = BoardPoints();
    cv::projectPoints(view.object_points, pose.rvec, pose.tvec, kTruth.K(), kTruth.DistCoeffs(), view.image_points);
    for (cv::Point2f& p : view.image_points) p += cv::Point2f(noise(random), noise(random));
    views.push_back(view);
  }
  return views;
}

CalibrationResult Fit(const std::vector<BoardDetection>& views) {
  CalibrationOptions options;
  options.reject_factor = 100;  // Gaussian noise only: keep every view, as the covariance assumes
  return CalibrateDetections(views, {}, kTruth.Size(), options);
}

TEST(ProjectionUncertainty, BoardsOnlyInTheMiddleLeaveTheCornersUncertainAndSaySo) {
  std::mt19937 random(7);
  const CalibrationResult middle = Fit(Observe(Poses(0.1), 0.2, random));
  const ProjectionUncertainty u = EstimateProjectionUncertainty(middle);
  EXPECT_NEAR(u.corner_noise_px, 0.2, 0.03);
  EXPECT_GT(u.worst_px, 5 * u.centre_px);
  ASSERT_FALSE(u.poor_regions.empty());
  EXPECT_EQ(std::find(u.poor_regions.begin(), u.poor_regions.end(), "centre"), u.poor_regions.end());
  const std::string warning = u.Warning();
  EXPECT_NE(warning.find(u.poor_regions.front()), std::string::npos) << warning;
  EXPECT_NE(warning.find("show the board"), std::string::npos) << warning;

  std::vector<BoardPose> across = Poses(0.9);
  for (const BoardPose& pose : Poses(0.5)) across.push_back(pose);
  const CalibrationResult spread = Fit(Observe(across, 0.2, random));
  const ProjectionUncertainty good = EstimateProjectionUncertainty(spread);
  EXPECT_LT(good.worst_px, u.worst_px / 3);
  EXPECT_TRUE(good.poor_regions.empty()) << good.Summary();
  EXPECT_EQ(good.Warning(), "");
  EXPECT_EQ(good.regions.size(), 9u);
  const cv::Mat picture = DrawProjectionUncertainty(good, spread.used_corners);
  EXPECT_EQ(picture.size(), kTruth.Size());
}

// The predicted uncertainty is the spread of the projection over calibrations of the same boards
// with fresh noise, the point held where the boards' frames put it (as the prediction holds it).
TEST(ProjectionUncertainty, MatchesTheSpreadOfRepeatedCalibrations) {
  const std::vector<BoardPose> poses = Poses(0.5);
  const double distance = 1.0;
  std::mt19937 random(11);
  const ProjectionUncertainty predicted = EstimateProjectionUncertainty(Fit(Observe(poses, 0.3, random)),
                                                                       {.distance_m = distance, .grid_columns = 4});
  const int last_row = predicted.grid.rows - 1, last_column = predicted.grid.cols - 1;
  const std::vector<cv::Point2d> pixels = {{319.5, 239.5}, predicted.GridPoint(0, 0),
                                           predicted.GridPoint(last_row, last_column)};
  std::vector<std::vector<cv::Point2d>> seen(pixels.size());
  for (int trial = 0; trial < 60; ++trial) {
    const CalibrationResult r = Fit(Observe(poses, 0.3, random));
    for (size_t k = 0; k < pixels.size(); ++k) {
      const Eigen::Vector2d n = kTruth.PixelToNormalized({pixels[k].x, pixels[k].y});
      const cv::Vec3d point(n.x() * distance, n.y() * distance, distance);
      cv::Vec3d moved(0, 0, 0);
      for (size_t i = 0; i < poses.size(); ++i) {
        cv::Matx33d truth_rotation, fit_rotation;
        cv::Rodrigues(poses[i].rvec, truth_rotation);
        cv::Rodrigues(r.rvecs[i], fit_rotation);
        moved += fit_rotation * (truth_rotation.t() * (point - poses[i].tvec)) + r.tvecs[i];
      }
      moved *= 1.0 / poses.size();
      const Eigen::Vector2d q = r.camera.Project({moved[0], moved[1], moved[2]});
      seen[k].emplace_back(q.x(), q.y());
    }
  }
  for (size_t k = 0; k < pixels.size(); ++k) {
    cv::Mat samples(static_cast<int>(seen[k].size()), 2, CV_64F, seen[k].data());
    cv::Mat covariance, mean;
    cv::calcCovarMatrix(samples, covariance, mean, cv::COVAR_NORMAL | cv::COVAR_ROWS | cv::COVAR_SCALE);
    Eigen::Matrix2d v;
    v << covariance.at<double>(0, 0), covariance.at<double>(0, 1), covariance.at<double>(1, 0), covariance.at<double>(1, 1);
    const double measured = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(v).eigenvalues().maxCoeff());
    const double expected = k == 0   ? predicted.centre_px
                            : k == 1 ? predicted.grid.at<double>(0, 0)
                                     : predicted.grid.at<double>(last_row, last_column);
    EXPECT_NEAR(measured, expected, 0.35 * expected) << "pixel " << pixels[k];
  }
}

TEST(ProjectionUncertainty, WithoutThePosesItIsAnError) {
  CalibrationResult empty;
  empty.camera = kTruth;
  EXPECT_THROW(EstimateProjectionUncertainty(empty), CalibrationError);
  UncertaintyOptions options;
  options.distance_m = 0;
  EXPECT_THROW(options.Check(), OptionError);
}

}  // namespace
}  // namespace arview::calib
