#include "anim/character.h"
#include "anim_authoring/yaml.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

namespace arview::authoring::yaml {
namespace {

TEST(Yaml, BlockAndFlow) {
  const Node n = Parse(R"(# scene
characters:
  - name: fox   # comment
    scale: 0.01
    anchor:
      position: [1, 2.5, -3]
    weights: {mode: local, alpha: 3}
    keys:
    - viewpoint: [0, 0, 1]
      clip: "Survey # not a comment"
    - azimuth: 90
      clip: 'it''s'
  - name: second
list:
  - a
  - [b, c]
empty:
)", "s.yaml");
  ASSERT_TRUE(n.IsMapping());
  const Node* chars = n.Find("characters");
  ASSERT_TRUE(chars && chars->IsSequence());
  ASSERT_EQ(chars->items.size(), 2u);
  const Node& fox = chars->items[0];
  EXPECT_EQ(fox.line, 3);
  EXPECT_EQ(fox.Find("name")->scalar, "fox");
  EXPECT_EQ(fox.Find("scale")->scalar, "0.01");
  EXPECT_EQ(fox.Find("scale")->line, 4);
  const Node* pos = fox.Find("anchor")->Find("position");
  ASSERT_TRUE(pos->IsSequence());
  EXPECT_EQ(pos->items[1].scalar, "2.5");
  EXPECT_EQ(fox.Find("weights")->Find("mode")->scalar, "local");
  const Node* keys = fox.Find("keys");
  ASSERT_EQ(keys->items.size(), 2u);
  EXPECT_EQ(keys->items[0].Find("clip")->scalar, "Survey # not a comment");
  EXPECT_TRUE(keys->items[0].Find("clip")->quoted);
  EXPECT_FALSE(fox.Find("name")->quoted);
  EXPECT_EQ(keys->items[1].Find("clip")->scalar, "it's");
  EXPECT_EQ(keys->items[1].line, 11);
  EXPECT_EQ(chars->items[1].Find("name")->scalar, "second");
  EXPECT_EQ(n.Find("list")->items[1].items[1].scalar, "c");
  EXPECT_TRUE(n.Find("empty")->IsScalar());
  EXPECT_EQ(n.Find("empty")->scalar, "");
  EXPECT_EQ(n.Find("empty")->line, 17);
}

void ExpectError(const std::string& text, const std::string& message) {
  try {
    Parse(text, "bad.yaml");
    FAIL() << "no error for: " << text;
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

TEST(Yaml, Errors) {
  ExpectError("a: 1\na: 2\n", "bad.yaml:2: duplicate key 'a'");
  ExpectError("a: {x: 1, y: 2, x: 3}\n", "bad.yaml:1: duplicate key 'x'");
  ExpectError("a:\n  b: 1\n  c: 2\n  b: 3\n", "bad.yaml:4: duplicate key 'b'");
  ExpectError("a:\n\tb: 1\n", "bad.yaml:2:");
  ExpectError("a: [1, 2\n", "bad.yaml:");
  ExpectError("a: 1\n  b: 2\n", "bad.yaml:2:");
  ExpectError("a: 'x\n", "bad.yaml:1: unterminated quoted string");
  ExpectError("a: 1\nb: \"x\n\n", "bad.yaml:2: unterminated quoted string");
  ExpectError("a: &x 1\nb: *x\n", "bad.yaml:1: anchors");
  ExpectError("a: !!int 1\n", "bad.yaml:1: anchors, aliases and tags");
  ExpectError("a: 1\n---\nb: 2\n", "bad.yaml:2: only one YAML document");
  ExpectError("a:\n  - 1\n  b: 2\n", "bad.yaml:3:");
  ExpectError("? [a, b]\n: 1\n", "bad.yaml:1: mapping keys must be plain names");
}

TEST(Yaml, EmptyDocumentIsEmptyMapping) {
  EXPECT_TRUE(Parse("# nothing\n\n", "e.yaml").IsMapping());
  EXPECT_TRUE(Parse("", "e.yaml").IsMapping());
}

// yaml-cpp's recursive parser overflows the stack thousands of levels deep (issue 17): the
// pre-scan refuses the file first, naming the line where it goes past the limit.
TEST(Yaml, DeepNestingIsRefusedBeforeParsing) {
  std::string block;  // 2,800 levels (one space each: 3.9 MB, under the size limit)
  for (int i = 0; i < 2800; ++i) block += std::string(i, ' ') + "k:\n";
  ExpectError(block, "bad.yaml:65: nested deeper than 64 levels");
  ExpectError(std::string(10000, '[') + std::string(10000, ']') + "\n", "bad.yaml:1: nested deeper than 64 levels");
  ExpectError("a: " + std::string(10000, '{') + "\n", "bad.yaml:1: nested deeper than 64 levels");
  std::string dashes;
  for (int i = 0; i < 3000; ++i) dashes += "- ";
  ExpectError(dashes + "x\n", "bad.yaml:1: nested deeper than 64 levels");
  // Flow nesting across lines counts too.
  std::string lines = "a:\n";
  for (int i = 0; i < 100; ++i) lines += "  [\n";
  ExpectError(lines, "bad.yaml:64: nested deeper than 64 levels");
  // 60 levels parse.
  std::string ok;
  for (int i = 0; i < 60; ++i) ok += std::string(2 * i, ' ') + "k:\n";
  EXPECT_NO_THROW(Parse(ok, "ok.yaml"));
  EXPECT_NO_THROW(Parse("a: " + std::string(60, '[') + std::string(60, ']') + "\n", "ok.yaml"));
}

TEST(Yaml, DepthScanIgnoresBracketsInScalarsAndQuotes) {
  EXPECT_EQ(ScanNestingDepth("clip: Walk[1\nname: 'x[[[['\nc: \"{{{\"\n# [[[[\n").max_depth, 1);
  EXPECT_EQ(ScanNestingDepth("a:\n  b: [1, [2, {c: 3}]]\n").max_depth, 5);
  EXPECT_EQ(ScanNestingDepth("- - - x\n").max_depth, 4);  // three sequences and the scalar
}

TEST(Yaml, FileLimits) {
  const auto dir = std::filesystem::temp_directory_path() / ("yaml_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto big = dir / "big.yaml";
  {
    std::ofstream out(big);
    out << "a: \"" << std::string(kMaxFileBytes, 'x') << "\"\n";
  }
  try {
    ParseFile(big);
    FAIL();
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("big.yaml: " + std::to_string(kMaxFileBytes + 6) + " bytes; scene files are limited"),
              std::string::npos)
        << e.what();
  }
  try {
    ParseFile(dir);
    FAIL();
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseFile("/dev/zero"), anim::Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace arview::authoring::yaml
