#include "anim_authoring/yaml.h"

#include "anim/character.h"  // Error

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/mark.h>
#include <yaml-cpp/parser.h>

#include <fstream>
#include <set>
#include <sstream>

namespace arview::authoring::yaml {
namespace {

// Builds our Node tree from yaml-cpp's events, refusing what scene files do not allow.
class TreeBuilder : public YAML::EventHandler {
 public:
  explicit TreeBuilder(std::string file) : file_(std::move(file)) {}

  bool has_root() const { return has_root_; }
  Node TakeRoot() { return std::move(root_); }

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}

  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    NoAnchor(mark, anchor);
    Node n;  // `key:` with nothing (or ~, null): an empty scalar, on the key's line
    n.line = Line(mark);
    Add(std::move(n), /*is_null=*/true);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    Fail(Line(mark), "anchors, aliases and tags are not supported");
  }
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                const std::string& value) override {
    NoAnchor(mark, anchor);
    NoTag(mark, tag);
    Node n;
    n.line = Line(mark);
    n.scalar = value;
    n.quoted = tag == "!";  // yaml-cpp tags quoted scalars "!", plain ones "?"
    Add(std::move(n), false);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    Open(mark, tag, anchor, Node::Kind::kSequence);
  }
  void OnSequenceEnd() override { Close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    Open(mark, tag, anchor, Node::Kind::kMapping);
  }
  void OnMapEnd() override { Close(); }

  [[noreturn]] void Fail(int line, const std::string& what) const {
    throw anim::Error(file_ + ":" + std::to_string(line) + ": " + what);
  }

 private:
  struct Frame {
    Node node;
    bool has_key = false;  // mappings: a key read, its value pending
    std::string key;
    int key_line = 0;
    std::set<std::string> keys;
  };

  static int Line(const YAML::Mark& mark) { return mark.line + 1; }

  void NoAnchor(const YAML::Mark& mark, YAML::anchor_t anchor) const {
    if (anchor != YAML::NullAnchor) Fail(Line(mark), "anchors, aliases and tags are not supported");
  }
  void NoTag(const YAML::Mark& mark, const std::string& tag) const {
    if (!tag.empty() && tag != "?" && tag != "!") Fail(Line(mark), "anchors, aliases and tags are not supported");
  }

  void Open(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor, Node::Kind kind) {
    NoAnchor(mark, anchor);
    NoTag(mark, tag);
    if (!stack_.empty() && stack_.back().node.IsMapping() && !stack_.back().has_key)
      Fail(Line(mark), "mapping keys must be plain names, not lists or mappings");
    Frame f;
    f.node.kind = kind;
    f.node.line = Line(mark);
    stack_.push_back(std::move(f));
  }

  void Close() {
    Node n = std::move(stack_.back().node);
    stack_.pop_back();
    Add(std::move(n), false);
  }

  void Add(Node n, bool is_null) {
    if (stack_.empty()) {
      root_ = std::move(n);
      has_root_ = true;
      return;
    }
    Frame& top = stack_.back();
    if (top.node.IsSequence()) {
      top.node.items.push_back(std::move(n));
      return;
    }
    if (!top.has_key) {
      if (n.scalar.empty()) Fail(n.line, "empty key");
      if (!top.keys.insert(n.scalar).second) Fail(n.line, "duplicate key '" + n.scalar + "'");
      top.key = std::move(n.scalar);
      top.key_line = n.line;
      top.has_key = true;
      return;
    }
    if (is_null) n.line = top.key_line;
    top.node.entries.emplace_back(std::move(top.key), std::move(n));
    top.has_key = false;
  }

  std::string file_;
  std::vector<Frame> stack_;
  Node root_;
  bool has_root_ = false;
};

bool IsFlowOpen(char c) { return c == '[' || c == '{'; }
bool IsFlowClose(char c) { return c == ']' || c == '}'; }

}  // namespace

DepthScan ScanNestingDepth(const std::string& text, int limit) {
  DepthScan scan;
  std::vector<std::size_t> block;  // columns of the open block levels
  int flow = 0;
  char quote = 0;  // open quote carried across lines
  int quote_line = 0;
  std::size_t start = 0;
  for (int line = 1; start <= text.size(); ++line) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view s(text.data() + start, end - start);
    std::size_t i = 0;
    while (i < s.size() && s[i] == ' ') ++i;
    const bool content = i < s.size() && s[i] != '#' && s[i] != '\r';
    if (content && flow == 0 && quote == 0) {
      // Block structure: a line at column c closes the levels at or right of c and opens one;
      // each "- " or "? " on the line opens one more (`- - - x` nests three deep on one line).
      auto open_at = [&](std::size_t column) {
        while (!block.empty() && block.back() >= column) block.pop_back();
        block.push_back(column);
      };
      open_at(i);
      while (i + 1 < s.size() && (s[i] == '-' || s[i] == '?') && s[i + 1] == ' ') {
        i += 2;
        while (i < s.size() && s[i] == ' ') ++i;
        if (i < s.size()) open_at(i);
      }
    }
    // Flow brackets: only where a flow collection can begin (inside one, or where a value or
    // an item starts), so that a plain scalar such as `clip: Walk[1]` does not count.
    char previous = 0;  // last non-space character outside quotes on this line
    for (; content && i < s.size(); ++i) {
      const char c = s[i];
      if (quote) {
        if (quote == '"' && c == '\\') ++i;
        else if (c == quote) quote = 0;
        continue;
      }
      if (c == '#' && (i == 0 || s[i - 1] == ' ' || s[i - 1] == '\t')) break;
      if (c == '"' || c == '\'') {
        if (flow > 0 || previous == 0 || previous == ':' || previous == '-' || previous == ',' || IsFlowOpen(previous)) {
          quote = c;
          quote_line = line;
        }
      } else if (IsFlowOpen(c) && (flow > 0 || previous == 0 || previous == ':' || previous == '-' || previous == '?')) {
        ++flow;
      } else if (IsFlowClose(c) && flow > 0) {
        --flow;
      }
      if (c != ' ' && c != '\t') previous = c;
      const int depth = static_cast<int>(block.size()) + flow;
      if (depth > scan.max_depth) scan.max_depth = depth;
      if (depth > limit && scan.first_line_over == 0) scan.first_line_over = line;
    }
    const int depth = static_cast<int>(block.size()) + flow;
    if (depth > scan.max_depth) scan.max_depth = depth;
    if (depth > limit && scan.first_line_over == 0) scan.first_line_over = line;
    if (scan.first_line_over) return scan;  // nothing after it matters
    start = end + 1;
  }
  if (quote) scan.unterminated_quote_line = quote_line;
  return scan;
}

const Node* Node::Find(const std::string& key) const {
  for (const auto& [k, v] : entries)
    if (k == key) return &v;
  return nullptr;
}

Node Parse(const std::string& text, const std::string& file) {
  if (text.size() > kMaxFileBytes)
    throw anim::Error(file + ": " + std::to_string(text.size()) + " bytes; scene files are limited to " +
                std::to_string(kMaxFileBytes) + " bytes");
  const DepthScan depth = ScanNestingDepth(text, kMaxDepth);
  if (depth.first_line_over)
    throw anim::Error(file + ":" + std::to_string(depth.first_line_over) + ": nested deeper than " + std::to_string(kMaxDepth) +
                " levels");
  if (depth.unterminated_quote_line)
    throw anim::Error(file + ":" + std::to_string(depth.unterminated_quote_line) + ": unterminated quoted string");
  std::istringstream in(text);
  TreeBuilder builder(file);
  try {
    YAML::Parser parser(in);
    if (!parser.HandleNextDocument(builder) || !builder.has_root()) {
      Node empty;
      empty.kind = Node::Kind::kMapping;
      return empty;
    }
    // A second document (after `---`) is refused: a scene is one document.
    TreeBuilder second(file);
    if (parser.HandleNextDocument(second)) {
      const std::size_t at = text.find("\n---", 0);
      int line = 1;
      for (std::size_t i = 0; i < at && i < text.size(); ++i) line += text[i] == '\n';
      builder.Fail(at == std::string::npos ? 1 : line + 1, "only one YAML document is supported");
    }
  } catch (const YAML::Exception& e) {
    throw anim::Error(file + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  Node root = builder.TakeRoot();
  if (root.IsScalar() && root.scalar.empty() && !root.quoted) {
    Node empty;  // a document holding only comments, or `~`
    empty.kind = Node::Kind::kMapping;
    return empty;
  }
  return root;
}

Node ParseFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw anim::Error(path.string() + ": no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw anim::Error(path.string() + ": not a regular file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw anim::Error(path.string() + ": cannot read its size: " + ec.message());
  if (size > kMaxFileBytes)
    throw anim::Error(path.string() + ": " + std::to_string(size) + " bytes; scene files are limited to " +
                std::to_string(kMaxFileBytes) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw anim::Error(path.string() + ": cannot open for reading");
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path.string());
}

Node::Node() = default;
Node::Node(const Node&) = default;
Node::Node(Node&&) noexcept = default;
Node& Node::operator=(const Node&) = default;
Node& Node::operator=(Node&&) noexcept = default;
Node::~Node() = default;

}  // namespace arview::authoring::yaml
