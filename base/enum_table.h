#pragma once
// Enum ↔ string, written once per enum (as COLMAP's util/enum_utils.h). Beside the enum, in its
// own namespace, declare its table as a function found by argument-dependent lookup:
//
//   enum class MatcherKind { kAuto, kSequential, kExhaustive };
//   constexpr auto EnumNames(MatcherKind) {
//     return arview::EnumTable<MatcherKind, 3>{{{MatcherKind::kAuto, "auto"},
//                                               {MatcherKind::kSequential, "sequential"},
//                                               {MatcherKind::kExhaustive, "exhaustive"}}};
//   }
//
// then arview::ToString(kind) gives "sequential", arview::ParseEnum<MatcherKind>("exhaustive",
// "--matcher") gives the value or throws, and EnumNameList<MatcherKind>() gives
// "auto, sequential or exhaustive" for messages. One naming scheme: lower case, words joined by
// '_', as the command line and the files spell them.

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "base/error.h"

namespace arview {

template <typename E>
struct EnumName {
  E value;
  std::string_view name;
};

template <typename E, std::size_t N>
using EnumTable = std::array<EnumName<E>, N>;

// The name of `value`; "?" only for a value outside the enum's table (a cast integer).
template <typename E>
std::string ToString(E value) {
  for (const auto& entry : EnumNames(E{}))
    if (entry.value == value) return std::string(entry.name);
  return "?";
}

template <typename E>
std::optional<E> EnumFromString(std::string_view text) {
  for (const auto& entry : EnumNames(E{}))
    if (entry.name == text) return entry.value;
  return std::nullopt;
}

// "a, b or c": the accepted names, for messages.
template <typename E>
std::string EnumNameList() {
  const auto table = EnumNames(E{});
  std::string out;
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (i > 0) out += i + 1 == table.size() ? " or " : ", ";
    out += table[i].name;
  }
  return out;
}

// The value named `text`, or throws ErrorType("<what> '<text>' is not one of a, b or c").
// ErrorType defaults to arview::Error; modules pass their own subclass.
template <typename E, typename ErrorType = Error>
E ParseEnum(std::string_view text, std::string_view what) {
  if (const std::optional<E> value = EnumFromString<E>(text)) return *value;
  throw ErrorType(std::string(what) + " '" + std::string(text) + "' is not one of " + EnumNameList<E>());
}

}  // namespace arview
