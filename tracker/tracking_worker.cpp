#include "tracker/tracking_worker.h"

#include <opencv2/video/tracking.hpp>

#include "tracker/timing.h"

namespace arview::tracker {

std::vector<cv::Mat> FlowPyramid(const cv::Mat& gray, int window_px, int levels) {
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(gray, pyramid, cv::Size(window_px, window_px), levels);
  return pyramid;
}

TrackingWorker::TrackingWorker(const map::Map& map, const calib::Camera& camera, const map::DescriptorIndex& index,
                               const RelocalizerOptions& relocalization, const FeatureOptions& guided_features,
                               FlowSettings flow)
    : relocalizer_(map, camera, index, relocalization), guided_extractor_(guided_features), flow_(flow) {}

std::future<TrackingWorker::Extracted> TrackingWorker::ExtractAhead(const cv::Mat& gray) {
  return thread_.Submit<Extracted>([this, image = gray.clone()] {
    const double cpu_start = ThreadCpuMilliseconds();
    Extracted out;
    out.features = relocalizer_.Extract(image, guided_extractor_);
    out.cpu_ms = ThreadCpuMilliseconds() - cpu_start;
    return out;
  });
}

std::future<TrackingWorker::Relocalized> TrackingWorker::Relocalize(const cv::Mat& gray) {
  return thread_.Submit<Relocalized>([this, image = gray.clone()] {
    const double cpu_start = ThreadCpuMilliseconds();
    Relocalized out;
    out.relocalization = relocalizer_.Relocalize(image);
    if (out.relocalization.pose.ok) out.pyramid = FlowPyramid(image, flow_.window_px, flow_.levels);
    out.cpu_ms = ThreadCpuMilliseconds() - cpu_start;
    return out;
  });
}

}  // namespace arview::tracker
