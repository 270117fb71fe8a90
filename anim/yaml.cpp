#include "anim/yaml.h"

#include "anim/character.h"  // Error

#include <fstream>
#include <set>
#include <sstream>

namespace arview::anim::yaml {
namespace {

struct Line {
  int number = 0;   // 1-based
  int indent = 0;
  std::string text; // without indentation and comment, right-trimmed
};

std::string RightTrim(std::string s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s;
}

std::string Trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && s[a] == ' ') ++a;
  while (b > a && s[b - 1] == ' ') --b;
  return s.substr(a, b - a);
}

class Parser {
 public:
  Parser(const std::string& text, std::string file) : file_(std::move(file)) { Split(text); }

  Node Document() {
    if (lines_.empty()) {
      Node n;
      n.kind = Node::Kind::kMapping;
      return n;
    }
    if (lines_[0].indent != 0) Fail(lines_[0].number, "the document must start at column 1");
    Node n = Block(0);
    if (pos_ < lines_.size()) Fail(lines_[pos_].number, "unexpected indentation or content");
    return n;
  }

 private:
  [[noreturn]] void Fail(int line, const std::string& what) const {
    throw Error(file_ + ":" + std::to_string(line) + ": " + what);
  }

  // Removes comments (a `#` at the start or after a space, outside quotes).
  std::string StripComment(const std::string& s, int number) const {
    char quote = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const char c = s[i];
      if (quote) {
        if (c == '\\' && quote == '"') ++i;
        else if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '#' && (i == 0 || s[i - 1] == ' ')) {
        return s.substr(0, i);
      }
    }
    if (quote) Fail(number, "unterminated quoted string");
    return s;
  }

  void Split(const std::string& text) {
    std::istringstream in(text);
    std::string raw;
    int number = 0;
    while (std::getline(in, raw)) {
      ++number;
      std::size_t indent = 0;
      while (indent < raw.size() && raw[indent] == ' ') ++indent;
      if (indent < raw.size() && raw[indent] == '\t') Fail(number, "tab in indentation (use spaces)");
      std::string body = RightTrim(StripComment(raw.substr(indent), number));
      if (body.empty()) continue;
      if (body == "---" && lines_.empty()) continue;
      if (body == "---" || body == "...") Fail(number, "only one YAML document is supported");
      if (body[0] == '&' || body[0] == '*' || body[0] == '!' || body[0] == '|' || body[0] == '>')
        Fail(number, "anchors, aliases, tags and block scalars are not supported");
      lines_.push_back({number, static_cast<int>(indent), body});
    }
  }

  static bool IsSeqItem(const std::string& t) { return t == "-" || t.rfind("- ", 0) == 0; }

  // Position of the `:` that ends a mapping key (followed by a space or end of line), outside
  // quotes and flow brackets; npos if none.
  static std::size_t KeyColon(const std::string& t) {
    char quote = 0;
    int depth = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const char c = t[i];
      if (quote) {
        if (c == '\\' && quote == '"') ++i;
        else if (c == quote) quote = 0;
        continue;
      }
      if (c == '"' || c == '\'') quote = c;
      else if (c == '[' || c == '{') ++depth;
      else if (c == ']' || c == '}') --depth;
      else if (c == ':' && depth == 0 && (i + 1 == t.size() || t[i + 1] == ' ')) return i;
    }
    return std::string::npos;
  }

  Node Block(int indent) {
    const Line& first = lines_[pos_];
    if (IsSeqItem(first.text)) return Sequence(indent);
    return Mapping(indent);
  }

  Node Sequence(int indent) {
    Node n;
    n.kind = Node::Kind::kSequence;
    n.line = lines_[pos_].number;
    while (pos_ < lines_.size() && lines_[pos_].indent == indent && IsSeqItem(lines_[pos_].text)) {
      Line& l = lines_[pos_];
      if (l.text == "-") {
        ++pos_;
        if (pos_ >= lines_.size() || lines_[pos_].indent <= indent) Fail(l.number, "empty sequence item");
        n.items.push_back(Block(lines_[pos_].indent));
        continue;
      }
      // "- rest": treat rest as a line of its own, indented to where it starts.
      std::size_t skip = 1;
      while (skip < l.text.size() && l.text[skip] == ' ') ++skip;
      l.indent += static_cast<int>(skip);
      l.text = l.text.substr(skip);
      if (IsSeqItem(l.text)) Fail(l.number, "nested '- - ' sequences are not supported");
      if (KeyColon(l.text) != std::string::npos) {
        n.items.push_back(Mapping(l.indent));
      } else {
        n.items.push_back(FlowValue(l.text, l.number));
        ++pos_;
      }
    }
    return n;
  }

  Node Mapping(int indent) {
    Node n;
    n.kind = Node::Kind::kMapping;
    n.line = lines_[pos_].number;
    std::set<std::string> seen;
    while (pos_ < lines_.size() && lines_[pos_].indent == indent) {
      const Line l = lines_[pos_];
      if (IsSeqItem(l.text)) Fail(l.number, "a sequence item where a 'key: value' was expected");
      const std::size_t colon = KeyColon(l.text);
      if (colon == std::string::npos) Fail(l.number, "expected 'key: value', got '" + l.text + "'");
      const std::string key = Unquote(Trim(l.text.substr(0, colon)), l.number);
      if (key.empty()) Fail(l.number, "empty key");
      if (!seen.insert(key).second) Fail(l.number, "duplicate key '" + key + "'");
      const std::string rest = Trim(l.text.substr(colon + 1));
      ++pos_;
      if (!rest.empty()) {
        n.entries.emplace_back(key, FlowValue(rest, l.number));
        continue;
      }
      // Nested block: deeper lines, or a sequence at the same indentation.
      if (pos_ < lines_.size() && (lines_[pos_].indent > indent ||
                                   (lines_[pos_].indent == indent && IsSeqItem(lines_[pos_].text)))) {
        const int child = lines_[pos_].indent;
        Node value = IsSeqItem(lines_[pos_].text) ? Sequence(child) : Mapping(child);
        n.entries.emplace_back(key, std::move(value));
      } else {
        Node empty;  // `key:` with nothing: an empty scalar
        empty.line = l.number;
        n.entries.emplace_back(key, std::move(empty));
      }
    }
    if (pos_ < lines_.size() && lines_[pos_].indent > indent)
      Fail(lines_[pos_].number, "unexpected indentation");
    return n;
  }

  std::string Unquote(const std::string& s, int number) const {
    if (s.size() >= 2 && (s[0] == '"' || s[0] == '\'')) {
      if (s.back() != s[0]) Fail(number, "bad quoted string " + s);
      std::string out;
      for (std::size_t i = 1; i + 1 < s.size(); ++i) {
        if (s[0] == '"' && s[i] == '\\' && i + 2 < s.size()) {
          const char e = s[++i];
          out += e == 'n' ? '\n' : e == 't' ? '\t' : e;
        } else if (s[0] == '\'' && s[i] == '\'' && i + 2 < s.size() && s[i + 1] == '\'') {
          out += '\'';
          ++i;
        } else {
          out += s[i];
        }
      }
      return out;
    }
    return s;
  }

  // A value on one line: flow collection or scalar.
  Node FlowValue(const std::string& text, int number) {
    std::size_t i = 0;
    Node n = Flow(text, i, number, /*in_flow=*/false);
    while (i < text.size() && text[i] == ' ') ++i;
    if (i != text.size()) Fail(number, "unexpected text after value: '" + text.substr(i) + "'");
    return n;
  }

  Node Flow(const std::string& t, std::size_t& i, int number, bool in_flow) {
    while (i < t.size() && t[i] == ' ') ++i;
    Node n;
    n.line = number;
    if (i < t.size() && (t[i] == '[' || t[i] == '{')) {
      const bool seq = t[i] == '[';
      const char close = seq ? ']' : '}';
      n.kind = seq ? Node::Kind::kSequence : Node::Kind::kMapping;
      ++i;
      std::set<std::string> seen;
      while (true) {
        while (i < t.size() && t[i] == ' ') ++i;
        if (i >= t.size()) Fail(number, std::string("missing '") + close + "' (flow collections must fit on one line)");
        if (t[i] == close) {
          ++i;
          break;
        }
        if (seq) {
          n.items.push_back(Flow(t, i, number, true));
        } else {
          const Node key = Flow(t, i, number, true);
          if (!key.IsScalar()) Fail(number, "flow mapping key must be a scalar");
          while (i < t.size() && t[i] == ' ') ++i;
          if (i >= t.size() || t[i] != ':') Fail(number, "expected ':' after key '" + key.scalar + "'");
          ++i;
          if (!seen.insert(key.scalar).second) Fail(number, "duplicate key '" + key.scalar + "'");
          n.entries.emplace_back(key.scalar, Flow(t, i, number, true));
        }
        while (i < t.size() && t[i] == ' ') ++i;
        if (i < t.size() && t[i] == ',') ++i;
        else if (i < t.size() && t[i] != close) Fail(number, std::string("expected ',' or '") + close + "'");
      }
      return n;
    }
    // Scalar.
    n.kind = Node::Kind::kScalar;
    if (i < t.size() && (t[i] == '"' || t[i] == '\'')) {
      const char q = t[i];
      std::size_t j = i + 1;
      for (; j < t.size(); ++j) {
        if (q == '"' && t[j] == '\\') ++j;
        else if (t[j] == q) {
          if (q == '\'' && j + 1 < t.size() && t[j + 1] == '\'') ++j;
          else break;
        }
      }
      if (j >= t.size()) Fail(number, "unterminated quoted string");
      n.scalar = Unquote(t.substr(i, j + 1 - i), number);
      n.quoted = true;
      i = j + 1;
      return n;
    }
    std::size_t j = i;
    while (j < t.size()) {
      const char c = t[j];
      if (in_flow && (c == ',' || c == ']' || c == '}')) break;
      if (in_flow && c == ':' && (j + 1 == t.size() || t[j + 1] == ' ')) break;
      ++j;
    }
    n.scalar = Trim(t.substr(i, j - i));
    if (!n.scalar.empty() && (n.scalar[0] == '&' || n.scalar[0] == '*' || n.scalar[0] == '!'))
      Fail(number, "anchors, aliases and tags are not supported");
    i = j;
    return n;
  }

  std::string file_;
  std::vector<Line> lines_;
  std::size_t pos_ = 0;
};

}  // namespace

const Node* Node::Find(const std::string& key) const {
  for (const auto& [k, v] : entries)
    if (k == key) return &v;
  return nullptr;
}

Node Parse(const std::string& text, const std::string& file) { return Parser(text, file).Document(); }

Node ParseFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(path.string() + ": no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading");
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path.string());
}

}  // namespace arview::anim::yaml
