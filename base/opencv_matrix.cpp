#include "base/opencv_matrix.h"

#include <exception>

#include <opencv2/core.hpp>

#include "base/input_guard.h"

namespace arview {

void ReadOpenCvMatrix(const cv::FileNode& node, cv::Mat& out, const std::string& what) {
  out.release();
  if (node.empty()) return;
  if (node.isMap()) {
    for (const char* key : {"rows", "cols", "dt", "data"}) {
      if (node[key].empty()) {
        throw InputError(what + ": the matrix has no '" + key + "' key (an !!opencv-matrix needs rows, cols, dt and data)");
      }
    }
  }
  try {
    node >> out;
  } catch (const cv::Exception& e) {
    throw InputError(what + ": is not an OpenCV matrix (OpenCV: " + e.msg + ")");
  } catch (const std::exception& e) {
    throw InputError(what + ": cannot be read as an OpenCV matrix (" + e.what() + ")");
  }
}

}  // namespace arview
