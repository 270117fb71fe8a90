#pragma once

#include "base/error.h"

namespace arview::render {

// Anything in render/ that cannot be done: no GL, a shader that does not compile, bad input.
struct RenderError : Error {
  using Error::Error;
};

}  // namespace arview::render
