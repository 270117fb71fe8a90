#pragma once

#include "base/error.h"

namespace arview::video {

// Anything in video/ that cannot be done: an output that cannot be opened or written (a video file,
// a PNG folder, the window), a frame of another size than the output was opened for.
struct VideoError : Error {
  using Error::Error;
};

}  // namespace arview::video
