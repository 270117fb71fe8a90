// TUM trajectories (groundtruth.txt, `arview eval`'s inputs) through recordings::ReadTum.
#include <exception>

#include "fuzz/fuzz_support.h"
#include "recordings/trajectory.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arview::fuzz::WriteInput("trajectory.txt", data, size);
  try {
    (void)arview::recordings::ReadTum(file);
  } catch (const std::exception&) {
  }
  return 0;
}
