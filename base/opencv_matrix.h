#pragma once
// A matrix from an OpenCV FileStorage node (camera files, room light files), read so that no
// library exception reaches the user: OpenCV 4.6 reads an !!opencv-matrix without looking for
// its keys, and one without `dt` made it throw std::length_error ("basic_string::_M_create" was
// the whole message). OpenCV's types are only declared here (base links OpenCV privately).

#include <string>

namespace cv {
class FileNode;
class Mat;
}  // namespace cv

namespace arview {

// Reads `node` into `out`. An empty node gives an empty matrix. A mapping must hold the keys
// rows, cols, dt and data; any failure of OpenCV's (cv::Exception or another std::exception) is
// an InputError "<what>: ..." naming the missing key or quoting the library.
void ReadOpenCvMatrix(const cv::FileNode& node, cv::Mat& out, const std::string& what);

}  // namespace arview
