#include "base/option_check.h"

#include <utility>

namespace arview {

OptionNames::OptionNames(std::map<std::string, std::string, std::less<>> names) : names_(std::move(names)) {}

std::string OptionNames::Path(std::string_view field) const { return prefix_ + std::string(field); }

std::string OptionNames::operator()(std::string_view field) const {
  const std::string path = Path(field);
  const auto named = names_.find(path);
  return named == names_.end() ? path : named->second;
}

OptionNames OptionNames::Nested(std::string_view member) const {
  OptionNames nested = *this;
  nested.prefix_ = Path(member) + ".";
  return nested;
}

}  // namespace arview
