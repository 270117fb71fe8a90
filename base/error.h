#pragma once
// One error base for every module. Library code throws an arview::Error (or a subclass) whose
// what() is the whole user-facing line: it names the file, device or flag and says what is
// wrong. Only app/cli/main.cpp catches, prints it and exits non-zero.

#include <stdexcept>
#include <string>

namespace arview {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace arview
