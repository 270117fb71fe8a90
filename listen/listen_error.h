#pragma once
// The error every listen/ function throws: a grammar that does not compile, a word the
// dictionary lacks, a model that is missing. what() is the whole line the user sees.

#include "base/error.h"

namespace arview::listen {

class ListenError : public Error {
 public:
  using Error::Error;
};

}  // namespace arview::listen
