#include "base/image_file.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <string_view>

#include "base/atomic_file.h"
#include "base/error.h"

namespace arview {

void WriteImageAtomically(const std::filesystem::path& file, const cv::Mat& image, const std::vector<int>& params) {
  if (image.empty()) throw Error(file.string() + ": cannot write an empty image");
  const std::string extension = file.extension().string();
  if (extension.empty()) throw Error(file.string() + ": no extension to choose the image format by");
  std::vector<unsigned char> encoded;
  bool ok = false;
  try {
    ok = cv::imencode(extension, image, encoded, params);
  } catch (const cv::Exception& e) {
    throw Error(file.string() + ": cannot encode the image (" + e.msg + ")");
  }
  if (!ok) throw Error(file.string() + ": cannot encode the image as " + extension);
  WriteFileAtomically(file, std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
}

}  // namespace arview
