#pragma once
// A strict reader for the subset of YAML that scene files use (anim/ must not depend on
// OpenCV, and no YAML library is on the project's list):
//   - block mappings `key: value` and block sequences `- item`, indented with spaces;
//   - a sequence item may open a mapping on its own line (`- key: value` then `  key2: v2`);
//   - flow sequences `[a, b, [c, d]]` and flow mappings `{a: 1, b: x}` on one line;
//   - plain, 'single'- and "double"-quoted scalars (escapes \" \\ \n \t); `#` comments.
// Anything else (tabs for indentation, anchors, tags, multi-line scalars, several documents,
// duplicate keys) is an error "file:line: what".

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace arview::anim::yaml {

struct Node {
  enum class Kind { kScalar, kSequence, kMapping };
  Kind kind = Kind::kScalar;
  std::string scalar;  // kScalar
  bool quoted = false;
  std::vector<Node> items;                             // kSequence
  std::vector<std::pair<std::string, Node>> entries;   // kMapping, in file order
  int line = 0;

  bool IsScalar() const { return kind == Kind::kScalar; }
  bool IsSequence() const { return kind == Kind::kSequence; }
  bool IsMapping() const { return kind == Kind::kMapping; }
  // nullptr when absent (or not a mapping).
  const Node* Find(const std::string& key) const;
};

// Parses `text`; `file` names it in error messages. An empty document is an empty mapping.
// Throws anim::Error.
Node Parse(const std::string& text, const std::string& file);
Node ParseFile(const std::filesystem::path& path);

}  // namespace arview::anim::yaml
