#include "calib/projection_uncertainty.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "base/stats.h"

namespace arview::calib {

namespace {

constexpr int kIntrinsics = 9;  // fx fy cx cy k1 k2 p1 p2 k3, as cv::calibrateCamera frees them
constexpr int kPose = 6;        // rvec, tvec of one board

// cv::projectPoints' Jacobian columns: rvec 0-2, tvec 3-5, fx fy 6-7, cx cy 8-9, distortion 10-14.
constexpr int kJacobianPose = 0, kJacobianIntrinsics = 6;

struct Fit {
  Eigen::MatrixXd covariance;  // of the intrinsics then each board's pose, per unit corner noise
  double corner_noise_px = 0;
};

// The Jacobian of every corner's projection with respect to every parameter, its normal matrix
// inverted, and the residuals' spread: the covariance of the least-squares solution.
Fit FitCovariance(const CalibrationResult& r) {
  const cv::Mat K(r.camera.K()), dist = r.camera.DistCoeffs();
  const int views = static_cast<int>(r.used_views.size());
  const int parameters = kIntrinsics + kPose * views;
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(parameters, parameters);
  double squared = 0;
  int coordinates = 0;
  for (int i = 0; i < views; ++i) {
    const BoardDetection& view = r.used_views[i];
    std::vector<cv::Point2f> projected;
    cv::Mat jacobian;
    cv::projectPoints(view.object_points, r.rvecs[i], r.tvecs[i], K, dist, projected, jacobian);
    Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(jacobian.rows, parameters);
    for (int row = 0; row < jacobian.rows; ++row) {
      for (int c = 0; c < kIntrinsics; ++c) rows(row, c) = jacobian.at<double>(row, kJacobianIntrinsics + c);
      for (int c = 0; c < kPose; ++c) rows(row, kIntrinsics + kPose * i + c) = jacobian.at<double>(row, kJacobianPose + c);
    }
    normal.noalias() += rows.transpose() * rows;
    for (size_t k = 0; k < projected.size(); ++k) {
      const cv::Point2f e = projected[k] - view.image_points[k];
      squared += e.dot(e);
    }
    coordinates += 2 * static_cast<int>(projected.size());
  }
  if (coordinates <= parameters) {
    throw CalibrationError("the projection uncertainty needs more corner coordinates (" + std::to_string(coordinates) +
                           ") than parameters (" + std::to_string(parameters) + ")");
  }
  Fit fit;
  // As mrcal: the noise is the residuals' standard deviation per coordinate.
  fit.corner_noise_px = std::sqrt(squared / coordinates);
  fit.covariance = normal.ldlt().solve(Eigen::MatrixXd::Identity(parameters, parameters));
  return fit;
}

// The largest standard deviation of a 2x2 covariance over all directions (mrcal's
// worst_direction_stdev).
double WorstDirectionStdev(const Eigen::Matrix2d& v) {
  const double mean = (v(0, 0) + v(1, 1)) / 2, half = (v(0, 0) - v(1, 1)) / 2;
  return std::sqrt(std::max(0.0, mean + std::sqrt(half * half + v(0, 1) * v(0, 1))));
}

// The 1-sigma uncertainty of projecting the point seen at `pixel`, `distance` in front, held
// fixed to the mean of the boards' frames.
double PixelUncertainty(const CalibrationResult& r, const Fit& fit, const cv::Point2d& pixel, double distance) {
  const Eigen::Vector2d normalized = r.camera.PixelToNormalized({pixel.x, pixel.y});
  const cv::Vec3d point(normalized.x() * distance, normalized.y() * distance, distance);
  const cv::Mat K(r.camera.K()), dist = r.camera.DistCoeffs();
  const int views = static_cast<int>(r.used_views.size());
  Eigen::MatrixXd gradient = Eigen::MatrixXd::Zero(2, fit.covariance.rows());
  for (int i = 0; i < views; ++i) {
    cv::Matx33d rotation;
    cv::Rodrigues(r.rvecs[i], rotation);
    // The point in board i's frame; board i's pose carries it back to the camera.
    const cv::Vec3d on_board = rotation.t() * (point - r.tvecs[i]);
    std::vector<cv::Point3d> object = {cv::Point3d(on_board)};
    std::vector<cv::Point2d> projected;
    cv::Mat jacobian;
    cv::projectPoints(object, r.rvecs[i], r.tvecs[i], K, dist, projected, jacobian);
    for (int row = 0; row < 2; ++row) {
      if (i == 0) {
        for (int c = 0; c < kIntrinsics; ++c) gradient(row, c) = jacobian.at<double>(row, kJacobianIntrinsics + c);
      }
      for (int c = 0; c < kPose; ++c) {
        gradient(row, kIntrinsics + kPose * i + c) = jacobian.at<double>(row, kJacobianPose + c) / views;
      }
    }
  }
  const Eigen::Matrix2d variance = gradient * fit.covariance * gradient.transpose();
  return WorstDirectionStdev(variance) * fit.corner_noise_px;
}

const char* RegionName(int row, int column) {
  static const char* kNames[3][3] = {{"top left", "top", "top right"},
                                     {"left", "centre", "right"},
                                     {"bottom left", "bottom", "bottom right"}};
  return kNames[row][column];
}

}  // namespace

void UncertaintyOptions::Check(const OptionNames& names) const {
  RequireOption(distance_m > 0, names("distance_m"), "positive", distance_m);
  RequireOption(grid_columns >= 3, names("grid_columns"), "at least 3", grid_columns);
  RequireOption(poor_px > 0, names("poor_px"), "positive", poor_px);
}

cv::Point2d ProjectionUncertainty::GridPoint(int row, int column) const {
  return {(column + 0.5) * image_size.width / grid.cols - 0.5, (row + 0.5) * image_size.height / grid.rows - 0.5};
}

std::string ProjectionUncertainty::Summary() const {
  std::string worst_region;
  double worst_value = -1;
  for (const auto& [name, value] : regions) {
    if (value > worst_value) {
      worst_value = value;
      worst_region = name;
    }
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "projection uncertainty at %.2g m: %.3f px at the centre, median %.3f, worst %.3f (%s region's median %.3f); "
                "corner noise %.3f px",
                options.distance_m, centre_px, median_px, worst_px, worst_region.c_str(), worst_value, corner_noise_px);
  return line;
}

std::string ProjectionUncertainty::Warning() const {
  if (poor_regions.empty()) return "";
  std::string names;
  for (size_t i = 0; i < poor_regions.size(); ++i) {
    names += (i == 0 ? "" : i + 1 == poor_regions.size() ? " and " : ", ") + poor_regions[i];
  }
  char limit[32];
  std::snprintf(limit, sizeof limit, "%.2g", options.poor_px);
  return "the calibration is poor at the " + names + " of the image (projection uncertainty above " + limit +
         " px there): few or no board corners were seen there; show the board in that part of the image, near its edge, "
         "and tilted";
}

ProjectionUncertainty EstimateProjectionUncertainty(const CalibrationResult& result, const UncertaintyOptions& options) {
  options.Check();
  if (result.used_views.empty() || result.used_views.size() != result.rvecs.size()) {
    throw CalibrationError("the projection uncertainty needs the calibration's views and board poses");
  }
  const Fit fit = FitCovariance(result);
  ProjectionUncertainty u;
  u.options = options;
  u.corner_noise_px = fit.corner_noise_px;
  u.image_size = result.camera.Size();
  const int columns = options.grid_columns;
  const int rows = std::max(3, static_cast<int>(std::lround(columns * static_cast<double>(u.image_size.height) /
                                                             u.image_size.width)));
  u.grid = cv::Mat(rows, columns, CV_64F);
  std::vector<double> all;
  std::vector<std::vector<double>> by_region(9);
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      const double value = PixelUncertainty(result, fit, u.GridPoint(row, column), options.distance_m);
      u.grid.at<double>(row, column) = value;
      all.push_back(value);
      by_region[(3 * row / rows) * 3 + 3 * column / columns].push_back(value);
    }
  }
  const cv::Point2d centre((u.image_size.width - 1) / 2.0, (u.image_size.height - 1) / 2.0);
  u.centre_px = PixelUncertainty(result, fit, centre, options.distance_m);
  u.median_px = Median(all);
  u.worst_px = *std::max_element(all.begin(), all.end());
  std::vector<std::pair<double, std::string>> poor;
  for (int region = 0; region < 9; ++region) {
    const double value = Median(by_region[region]);
    u.regions.emplace_back(RegionName(region / 3, region % 3), value);
    if (value > options.poor_px) poor.emplace_back(value, RegionName(region / 3, region % 3));
  }
  std::sort(poor.rbegin(), poor.rend());
  for (const auto& [value, name] : poor) u.poor_regions.push_back(name);
  return u;
}

cv::Mat DrawProjectionUncertainty(const ProjectionUncertainty& u, const std::vector<std::vector<cv::Point2f>>& corners) {
  cv::Mat fine;
  cv::resize(u.grid, fine, u.image_size, 0, 0, cv::INTER_CUBIC);
  const double top = 2 * u.options.poor_px;
  cv::Mat scaled;
  fine.convertTo(scaled, CV_8U, 255.0 / top);  // saturates at 2 x poor_px
  cv::Mat picture;
  cv::applyColorMap(scaled, picture, cv::COLORMAP_JET);
  cv::Mat poor_mask = fine > u.options.poor_px;
  std::vector<std::vector<cv::Point>> outline;
  cv::findContours(poor_mask, outline, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(picture, outline, -1, {255, 255, 255}, 2, cv::LINE_AA);
  for (const auto& view : corners) {
    for (const cv::Point2f& p : view) cv::circle(picture, p, 1, {0, 0, 0}, cv::FILLED);
  }
  const auto text = [&](const std::string& line, int y) {
    cv::putText(picture, line, {10, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 3, cv::LINE_AA);
    cv::putText(picture, line, {10, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1, cv::LINE_AA);
  };
  text(cv::format("projection uncertainty at %.2g m (px, 1 sigma, worst direction)", u.options.distance_m), 22);
  text(cv::format("centre %.3f  median %.3f  worst %.3f", u.centre_px, u.median_px, u.worst_px), 42);
  text(cv::format("white line: %.2g px; red: %.2g px and above", u.options.poor_px, top), 62);
  return picture;
}

}  // namespace arview::calib
