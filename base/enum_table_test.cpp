#include "base/enum_table.h"

#include <gtest/gtest.h>

namespace arview::enum_test {

enum class Colour { kRed, kDarkGreen, kBlue };
constexpr auto EnumNames(Colour) {
  return EnumTable<Colour, 3>{{{Colour::kRed, "red"}, {Colour::kDarkGreen, "dark_green"}, {Colour::kBlue, "blue"}}};
}

struct ColourError : Error {
  using Error::Error;
};

TEST(EnumTable, NamesAndParsesEveryValueBothWays) {
  for (Colour c : {Colour::kRed, Colour::kDarkGreen, Colour::kBlue}) {
    EXPECT_EQ(ParseEnum<Colour>(ToString(c), "colour"), c);
  }
  EXPECT_EQ(ToString(Colour::kDarkGreen), "dark_green");
}

TEST(EnumTable, AValueOutsideTheTableIsNamedQuestionMark) {
  EXPECT_EQ(ToString(static_cast<Colour>(17)), "?");
}

TEST(EnumTable, UnknownNameThrowsTheGivenErrorListingTheNames) {
  EXPECT_FALSE(EnumFromString<Colour>("Red").has_value());  // names are exact
  try {
    ParseEnum<Colour, ColourError>("purple", "--colour");
    FAIL() << "expected an error";
  } catch (const ColourError& e) {
    EXPECT_STREQ(e.what(), "--colour 'purple' is not one of red, dark_green or blue");
  }
}

TEST(EnumTable, NameListSaysTheAlternatives) {
  EXPECT_EQ(EnumNameList<Colour>(), "red, dark_green or blue");
}

}  // namespace arview::enum_test
