#pragma once
// Options structs check themselves, as COLMAP's do: `void Check(const OptionNames& names = {})
// const` throws an OptionError naming the option and what is wrong, and the library that takes
// the struct calls it before any work. A command calls it too, before reading any file, with
// the names of the flags that set the fields, so that the user reads "--working-size must be 0
// (full resolution) or at least 64 (got 32)" rather than a field's name.

#include <map>
#include <sstream>
#include <string>
#include <string_view>

#include "base/error.h"

namespace arview {

struct OptionError : Error {
  using Error::Error;
};

// What a Check() calls each field in its message: the field's path in the struct
// ("relocalization.sift_long_side"), or the caller's own name for it (a flag).
class OptionNames {
 public:
  OptionNames() = default;
  // field path → the caller's name for it; a field not listed is called by its path.
  explicit OptionNames(std::map<std::string, std::string, std::less<>> names);
  // The name of `field` of the struct being checked.
  std::string operator()(std::string_view field) const;
  // The names for a member struct's Check(): its fields are `member.field` here.
  OptionNames Nested(std::string_view member) const;

 private:
  std::string Path(std::string_view field) const;
  std::map<std::string, std::string, std::less<>> names_;
  std::string prefix_;  // "relocalization." inside RelocalizerOptions::Check
};

// Throws OptionError "<name> must be <requirement> (got <value>)" unless `ok`.
template <typename T>
void RequireOption(bool ok, const std::string& name, const std::string& requirement, const T& value) {
  if (ok) return;
  std::ostringstream message;
  message << name << " must be " << requirement << " (got " << value << ")";
  throw OptionError(message.str());
}

}  // namespace arview
