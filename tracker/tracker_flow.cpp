// The flow steps of Tracker, apart from tracker.cpp: the pyramids LK works on and following
// points from one frame into another.

#include <opencv2/video/tracking.hpp>

#include "tracker/tracker.h"

namespace arview::tracker {

std::vector<cv::Mat> Tracker::FlowPyramid(const cv::Mat& gray) const {
  const TrackingOptions& opt = options_.tracking;
  return tracker::FlowPyramid(gray, opt.lk_window_px, opt.lk_pyramid_levels);
}

std::vector<unsigned char> Tracker::FollowByLk(const std::vector<cv::Mat>& from_pyramid,
                                               const std::vector<cv::Mat>& to_pyramid,
                                               const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to,
                                               std::vector<float>* errors) const {
  const TrackingOptions& opt = options_.tracking;
  std::vector<unsigned char> status;
  std::vector<float> own_errors;
  std::vector<float>& error = errors ? *errors : own_errors;
  cv::calcOpticalFlowPyrLK(
      from_pyramid, to_pyramid, from, *to, status, error, cv::Size(opt.lk_window_px, opt.lk_window_px),
      opt.lk_pyramid_levels,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, opt.lk_max_iterations, 0.03),
      cv::OPTFLOW_USE_INITIAL_FLOW);
  return status;
}

int Tracker::FollowIntoFrame(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
                             const std::vector<cv::Point2f>& from, const std::vector<std::uint32_t>& point_ids,
                             std::vector<cv::Point2f> guesses, Correspondences* out,
                             const std::function<bool(std::size_t, const Eigen::Vector2d&)>& keep,
                             std::vector<float>* appended_errors) const {
  if (from.empty()) return 0;
  const calib::Camera& camera = resolution_.work();
  std::vector<float> errors;
  const std::vector<unsigned char> status = FollowByLk(from_pyramid, to_pyramid, from, &guesses, &errors);
  int added = 0;
  for (std::size_t i = 0; i < guesses.size(); ++i) {
    const Eigen::Vector2d px(guesses[i].x, guesses[i].y);
    if (!status[i] || !camera.InImage(px, 1.0) || (keep && !keep(i, px))) continue;
    out->pixels.push_back(px);
    out->points.push_back(map_.points[point_ids[i]].xyz);
    out->point_ids.push_back(point_ids[i]);
    if (appended_errors) appended_errors->push_back(errors[i]);
    ++added;
  }
  return added;
}

}  // namespace arview::tracker
