// map.png: the map seen from "above", i.e. along the normal of the plane the cameras move in.

#include "base/image_file.h"

#include "base/stats.h"

#include <Eigen/Eigenvalues>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "mapping/colmap_pipeline.h"

namespace arview::mapping {

namespace {

// Two in-plane axes (rows 0, 1) and the normal (row 2): the normal is the direction in which the
// camera centres spread least, turned to point where the cameras' "up" (−y) points on average.
// With fewer than 3 cameras the points decide the plane.
Eigen::Matrix3d ViewAxes(const map::Map& map) {
  std::vector<Eigen::Vector3d> samples;
  for (const map::Keyframe& k : map.keyframes) samples.push_back(k.pose.Center());
  if (samples.size() < 3) {
    for (const map::MapPoint& p : map.points) samples.push_back(p.xyz);
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& s : samples) mean += s;
  mean /= std::max<size_t>(1, samples.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& s : samples) cov += (s - mean) * (s - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);  // eigenvalues ascending
  Eigen::Vector3d normal = eig.eigenvectors().col(0);
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const map::Keyframe& k : map.keyframes) up += k.pose.CameraToWorldRotation() * Eigen::Vector3d(0, -1, 0);
  if (normal.dot(up) < 0) normal = -normal;
  Eigen::Vector3d a = eig.eigenvectors().col(2);
  Eigen::Vector3d b = normal.cross(a);
  Eigen::Matrix3d axes;
  axes.row(0) = a.transpose();
  axes.row(1) = b.transpose();
  axes.row(2) = normal.transpose();
  return axes;
}

}  // namespace

void WriteTopView(const map::Map& map, const std::filesystem::path& png, int size) {
  const Eigen::Matrix3d axes = ViewAxes(map);
  auto plane = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d((axes * p).head<2>()); };
  // The extent covers the cameras and all but the 1% outermost points on each side.
  std::vector<double> xs, ys;
  for (const map::MapPoint& p : map.points) {
    const Eigen::Vector2d q = plane(p.xyz);
    xs.push_back(q.x());
    ys.push_back(q.y());
  }
  double x0 = Percentile(xs, 0.01), x1 = Percentile(xs, 0.99), y0 = Percentile(ys, 0.01), y1 = Percentile(ys, 0.99);
  for (const map::Keyframe& k : map.keyframes) {
    const Eigen::Vector2d q = plane(k.pose.Center());
    x0 = std::min(x0, q.x()), x1 = std::max(x1, q.x()), y0 = std::min(y0, q.y()), y1 = std::max(y1, q.y());
  }
  const double span = std::max({x1 - x0, y1 - y0, 1e-9});
  const double margin = 0.05 * size;
  const double scale = (size - 2 * margin) / span;
  const Eigen::Vector2d centre(0.5 * (x0 + x1), 0.5 * (y0 + y1));
  auto pixel = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d q = (plane(p) - centre) * scale;
    // y of the image grows downwards; flip so that the view is not mirrored.
    return cv::Point(static_cast<int>(std::lround(size / 2.0 + q.x())), static_cast<int>(std::lround(size / 2.0 - q.y())));
  };

  cv::Mat image(size, size, CV_8UC3, cv::Scalar(255, 255, 255));
  for (const map::MapPoint& p : map.points) {
    const cv::Point px = pixel(p.xyz);
    if (px.x < 0 || px.y < 0 || px.x >= size || px.y >= size) continue;
    image.at<cv::Vec3b>(px) = cv::Vec3b(p.rgb[2], p.rgb[1], p.rgb[0]);
  }
  std::vector<cv::Point> path;
  for (const map::Keyframe& k : map.keyframes) path.push_back(pixel(k.pose.Center()));
  cv::polylines(image, path, false, cv::Scalar(200, 80, 0), 1, cv::LINE_AA);
  for (size_t i = 0; i < map.keyframes.size(); ++i) {
    const map::Keyframe& k = map.keyframes[i];
    // A short stroke along the viewing direction, projected into the view plane.
    const Eigen::Vector3d ahead = k.pose.Center() + k.pose.CameraToWorldRotation() * Eigen::Vector3d(0, 0, 0.04 * span);
    cv::line(image, path[i], pixel(ahead), cv::Scalar(0, 0, 220), 1, cv::LINE_AA);
    cv::circle(image, path[i], 3, i == 0 ? cv::Scalar(0, 160, 0) : cv::Scalar(200, 80, 0), cv::FILLED, cv::LINE_AA);
  }
  const std::string caption = std::to_string(map.keyframes.size()) + " keyframes, " +
                              std::to_string(map.points.size()) + " points (top view; green: first keyframe)";
  cv::putText(image, caption, cv::Point(10, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  WriteImageAtomically(png, image);
}

}  // namespace arview::mapping
