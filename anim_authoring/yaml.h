#pragma once
// Scene files are read with yaml-cpp (stella_vslam reads its config the same way); this layer
// adds what yaml-cpp does not give and users of our scene files rely on:
//   - every node carries its line, so that errors read "file:line: what";
//   - duplicate keys are refused (yaml-cpp keeps both entries silently);
//   - anchors, aliases and explicit tags are refused (an alias can expand a small file into an
//     exponentially large tree; no scene needs them);
//   - nesting depth and file size are bounded BEFORE yaml-cpp parses: its recursive-descent
//     parser overflows the stack on ~3,000 nested block levels or ~10,000 flow levels (issue 17),
//     so a cheap pre-scan of the text refuses anything deeper than kMaxDepth levels.
// The tree is built from yaml-cpp's event stream (YAML::Parser + EventHandler), which hands us
// the mark (line, column) of every node.

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace arview::authoring::yaml {

// Deeper than any scene needs (the deepest key path today is 5 levels); far below where
// yaml-cpp's recursion exhausts an 8 MB stack (thousands of levels).
inline constexpr int kMaxDepth = 64;
// Scene files are a few kilobytes; 4 MiB leaves room for thousands of keys and schedules.
inline constexpr std::size_t kMaxFileBytes = 4u << 20;

struct Node {
  enum class Kind { kScalar, kSequence, kMapping };
  Kind kind = Kind::kScalar;
  std::string scalar;  // kScalar
  bool quoted = false;
  std::vector<Node> items;                             // kSequence
  std::vector<std::pair<std::string, Node>> entries;   // kMapping, in file order
  int line = 0;                                        // 1-based

  // Defined in yaml.cpp, where Node is complete: `entries` holds pairs of Node, and libstdc++
  // under clang refuses to instantiate their destructor inside Node's own definition.
  Node();
  Node(const Node&);
  Node(Node&&) noexcept;
  Node& operator=(const Node&);
  Node& operator=(Node&&) noexcept;
  ~Node();

  bool IsScalar() const { return kind == Kind::kScalar; }
  bool IsSequence() const { return kind == Kind::kSequence; }
  bool IsMapping() const { return kind == Kind::kMapping; }
  // nullptr when absent (or not a mapping).
  const Node* Find(const std::string& key) const;
};

// Parses `text`; `file` names it in error messages. An empty document is an empty mapping.
// Throws anim::Error "file:line: what".
Node Parse(const std::string& text, const std::string& file);
// Refuses what is not a regular file, and files over kMaxFileBytes, before reading them.
Node ParseFile(const std::filesystem::path& path);

// The pre-scan: the deepest nesting (block indentation levels, sequence dashes and flow
// brackets together) and the 1-based line where it first exceeds `limit` (0 if it never does).
// Also finds a quoted scalar left open at the end of the text (yaml-cpp 0.7 accepts one).
struct DepthScan {
  int max_depth = 0;
  int first_line_over = 0;
  int unterminated_quote_line = 0;  // where the open quote began, 0 if none
};
DepthScan ScanNestingDepth(const std::string& text, int limit = kMaxDepth);

}  // namespace arview::authoring::yaml
