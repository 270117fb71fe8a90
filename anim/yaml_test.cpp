#include "anim/character.h"
#include "anim/yaml.h"

#include <gtest/gtest.h>

namespace arview::anim::yaml {
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
  EXPECT_EQ(keys->items[1].Find("clip")->scalar, "it's");
  EXPECT_EQ(keys->items[1].line, 11);
  EXPECT_EQ(chars->items[1].Find("name")->scalar, "second");
  EXPECT_EQ(n.Find("list")->items[1].items[1].scalar, "c");
  EXPECT_TRUE(n.Find("empty")->IsScalar());
  EXPECT_EQ(n.Find("empty")->scalar, "");
}

void ExpectError(const std::string& text, const std::string& message) {
  try {
    Parse(text, "bad.yaml");
    FAIL() << "no error for: " << text;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

TEST(Yaml, Errors) {
  ExpectError("a: 1\na: 2\n", "bad.yaml:2: duplicate key 'a'");
  ExpectError("a:\n\tb: 1\n", "bad.yaml:2: tab in indentation");
  ExpectError("a: [1, 2\n", "bad.yaml:1: missing ']'");
  ExpectError("a: 1\n  b: 2\n", "bad.yaml:2: unexpected indentation");
  ExpectError("a: 'x\n", "bad.yaml:1: unterminated");
  ExpectError("just text\n", "bad.yaml:1: expected 'key: value'");
  ExpectError("a: &x 1\n", "bad.yaml:1: anchors");
  ExpectError("a: 1\n---\nb: 2\n", "bad.yaml:2: only one YAML document");
  ExpectError("a:\n  - 1\n  b: 2\n", "bad.yaml:3:");
}

TEST(Yaml, EmptyDocumentIsEmptyMapping) {
  EXPECT_TRUE(Parse("# nothing\n\n", "e.yaml").IsMapping());
}

}  // namespace
}  // namespace arview::anim::yaml
