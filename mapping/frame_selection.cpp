#include "mapping/frame_selection.h"

#include "base/stats.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <set>

namespace arview::mapping {

FrameQuality MeasureFrame(const cv::Mat& image) {
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = image;
  }
  // Sharpness at a fixed scale, so that a frame size does not change the threshold's meaning.
  if (grey.cols > 640) {
    cv::resize(grey, grey, cv::Size(640, std::max(1, grey.rows * 640 / grey.cols)), 0, 0, cv::INTER_AREA);
  }
  FrameQuality q;
  cv::Mat laplacian;
  cv::Laplacian(grey, laplacian, CV_64F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(laplacian, mean, stddev);
  q.sharpness = stddev[0] * stddev[0];
  cv::resize(grey, q.thumbnail, cv::Size(64, 48), 0, 0, cv::INTER_AREA);
  return q;
}

namespace {

double MeanAbsDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  return cv::mean(diff)[0];
}

}  // namespace

std::vector<int> CapEvenly(const std::vector<int>& frames, int max_frames) {
  if (max_frames <= 0 || static_cast<int>(frames.size()) <= max_frames) return frames;
  std::vector<int> kept;
  const double step = static_cast<double>(frames.size()) / max_frames;
  for (int i = 0; i < max_frames; ++i) kept.push_back(frames[static_cast<size_t>(i * step)]);
  return kept;
}

FrameSelection SelectFrames(const std::vector<FrameQuality>& quality, const std::vector<int>& candidates,
                            const FrameSelectionOptions& options) {
  FrameSelection result;
  const int n = static_cast<int>(candidates.size());
  const int half = std::max(1, options.blur_window / 2);
  std::vector<int> sharp;
  for (int p = 0; p < n; ++p) {
    std::vector<double> window;
    for (int j = std::max(0, p - half); j <= std::min(n - 1, p + half); ++j) {
      window.push_back(quality.at(static_cast<size_t>(candidates[static_cast<size_t>(j)])).sharpness);
    }
    const double s = quality.at(static_cast<size_t>(candidates[static_cast<size_t>(p)])).sharpness;
    if (s < options.blur_ratio * Median(window)) {
      ++result.blurred;
    } else {
      sharp.push_back(candidates[static_cast<size_t>(p)]);
    }
  }
  std::vector<int> distinct;
  for (int f : sharp) {
    if (!distinct.empty() &&
        MeanAbsDifference(quality[static_cast<size_t>(f)].thumbnail,
                          quality[static_cast<size_t>(distinct.back())].thumbnail) < options.duplicate_threshold) {
      ++result.duplicates;
      continue;
    }
    distinct.push_back(f);
  }
  const int cap = options.max_frames;
  if (cap <= 0 || static_cast<int>(distinct.size()) <= cap) {
    result.frames = distinct;
    return result;
  }
  // The sharpest frame of each of `cap` equal stretches.
  const double step = static_cast<double>(distinct.size()) / cap;
  for (int b = 0; b < cap; ++b) {
    const auto begin = static_cast<size_t>(b * step);
    const auto end = std::max(begin + 1, static_cast<size_t>((b + 1) * step));
    int best = distinct[begin];
    for (size_t i = begin; i < end && i < distinct.size(); ++i) {
      if (quality[static_cast<size_t>(distinct[i])].sharpness > quality[static_cast<size_t>(best)].sharpness) {
        best = distinct[i];
      }
    }
    result.frames.push_back(best);
  }
  result.capped = static_cast<int>(distinct.size()) - cap;
  return result;
}

FrameSelection SelectVideoFrames(const recordings::Recording& recording, const std::vector<int>& candidates,
                                 const FrameSelectionOptions& options,
                                 const std::function<void(int, int)>& on_progress) {
  std::vector<int> wanted = candidates;
  if (wanted.empty()) {
    for (int i = 0; i < static_cast<int>(recording.frames.size()); ++i) wanted.push_back(i);
  }
  const int last = wanted.back();
  const std::string video = recording.FramePath(0).string();
  cv::VideoCapture cap(video);
  if (!cap.isOpened()) throw recordings::RecordingError(video + ": cannot open the video");
  std::vector<FrameQuality> quality(static_cast<size_t>(last) + 1);
  const std::set<int> wanted_set(wanted.begin(), wanted.end());
  cv::Mat frame;
  for (int i = 0; i <= last; ++i) {
    if (!cap.read(frame) || frame.empty()) {
      throw recordings::RecordingError(video + ": ends at frame " + std::to_string(i) + " but frames.txt lists " +
                                       std::to_string(recording.frames.size()) + " frames");
    }
    if (wanted_set.count(i)) quality[static_cast<size_t>(i)] = MeasureFrame(frame);
    if (on_progress) on_progress(i + 1, last + 1);
  }
  return SelectFrames(quality, wanted, options);
}

}  // namespace arview::mapping
