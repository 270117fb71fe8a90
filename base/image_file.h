#pragma once
// Images written atomically: encoded in memory by OpenCV (the format chosen by the file's
// extension, as cv::imwrite does), then written with WriteFileAtomically. The header names
// cv::Mat only, so modules that include base/ without OpenCV (anim/) do not see OpenCV.

#include <filesystem>
#include <vector>

namespace cv {
class Mat;
}

namespace arview {

// Throws arview::Error naming `file` if the extension has no encoder, the image is empty or the
// encoding or the write fails. `params` are cv::imwrite's (e.g. IMWRITE_PNG_COMPRESSION, 1).
void WriteImageAtomically(const std::filesystem::path& file, const cv::Mat& image, const std::vector<int>& params = {});

}  // namespace arview
