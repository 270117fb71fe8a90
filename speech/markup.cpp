#include "speech/markup.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>

namespace arview::speech {
namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
bool IsControl(char c) {
  const auto byte = static_cast<unsigned char>(c);
  return (byte < 0x20 && !IsSpace(c)) || byte == 0x7f;
}
bool IsLetter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool IsNameChar(char c) { return IsLetter(c) || (c >= '0' && c <= '9') || c == '_' || c == '-'; }

constexpr std::size_t kMaxNameBytes = 64;

// The attributes each tag takes; the first is the one it needs.
struct TagSyntax {
  TagKind kind;
  std::string_view target_attribute;  // required: what the tag names
  bool takes_intensity;
};
constexpr TagSyntax kTagSyntax[] = {
    {TagKind::kGesture, "name", false}, {TagKind::kFace, "expr", true}, {TagKind::kGaze, "at", false}};

const TagSyntax& SyntaxOf(TagKind kind) {
  for (const TagSyntax& syntax : kTagSyntax)
    if (syntax.kind == kind) return syntax;
  return kTagSyntax[0];
}

std::string AttributeList(const TagSyntax& syntax) {
  return std::string(syntax.target_attribute) + (syntax.takes_intensity ? " and intensity" : "");
}

class Parser {
 public:
  Parser(std::string_view markup, std::string_view origin) : markup_(markup), origin_(origin) {}

  MarkedLine Run() {
    if (markup_.size() > kMaxMarkupBytes)
      Fail(kMaxMarkupBytes, "the line is " + std::to_string(markup_.size()) + " bytes long, over the limit of " +
                                std::to_string(kMaxMarkupBytes));
    while (pos_ < markup_.size()) {
      const char c = markup_[pos_];
      if (c == '<') {
        ReadTag();
      } else if (c == '>') {
        Fail(pos_, "a '>' outside a tag");
      } else if (IsControl(c)) {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02x", static_cast<unsigned>(static_cast<unsigned char>(c)));
        Fail(pos_, std::string("a control byte ") + hex);
      } else {
        Append(c);
        ++pos_;
      }
    }
    return std::move(line_);
  }

 private:
  [[noreturn]] void Fail(std::size_t index, const std::string& problem) const {
    throw SpeechError(std::string(origin_) + ": " + problem + " at character " + std::to_string(index + 1));
  }

  void Append(char c) {
    if (line_.text.size() == kMaxSpokenBytes)
      Fail(pos_, "the text to speak is over the limit of " + std::to_string(kMaxSpokenBytes) + " bytes");
    const bool starts_word = !IsSpace(c) && (line_.text.empty() || IsSpace(line_.text.back()));
    line_.text.push_back(c);
    if (starts_word) line_.words.emplace_back();
    if (!IsSpace(c)) line_.words.back().push_back(c);
  }

  bool AtEnd() const { return pos_ >= markup_.size(); }
  char Peek() const { return markup_[pos_]; }

  std::string ReadName() {
    const std::size_t begin = pos_;
    while (!AtEnd() && IsNameChar(Peek())) ++pos_;
    return std::string(markup_.substr(begin, pos_ - begin));
  }

  void SkipSpaces() {
    while (!AtEnd() && IsSpace(Peek())) ++pos_;
  }

  // At the tag's '<'; leaves pos_ after its "/>".
  void ReadTag() {
    const std::size_t start = pos_++;
    if (!AtEnd() && Peek() == '/') Fail(start, "a closing tag: the tags close themselves, as <face expr=\"happy\"/>");
    const std::string name = ReadName();
    if (name.empty()) Fail(start, "a '<' that starts no tag");
    const std::optional<TagKind> kind = EnumFromString<TagKind>(name);
    if (!kind) Fail(start, "the unknown tag <" + name + "> (the tags are " + EnumNameList<TagKind>() + ")");
    const TagSyntax& syntax = SyntaxOf(*kind);
    MarkupTag tag{*kind, "", 1.0, 0, start + 1};
    bool has_target = false;
    bool has_intensity = false;
    while (true) {
      SkipSpaces();
      if (AtEnd() || Peek() == '<') Fail(start, "the tag <" + name + "> is not closed with \"/>\"");
      if (Peek() == '/') {
        ++pos_;
        if (AtEnd() || Peek() != '>') Fail(pos_ - 1, "a '/' not followed by '>' in the tag <" + name + ">");
        ++pos_;
        break;
      }
      if (Peek() == '>') Fail(start, "the tag <" + name + "> is not closed with \"/>\"");
      const std::size_t attribute_at = pos_;
      const std::string attribute = ReadName();
      if (attribute.empty()) Fail(pos_, "an unexpected character in the tag <" + name + ">");
      const bool is_target = attribute == syntax.target_attribute;
      const bool is_intensity = syntax.takes_intensity && attribute == "intensity";
      if (!is_target && !is_intensity)
        Fail(attribute_at, "the unknown attribute '" + attribute + "' of <" + name + "> (it takes " +
                               AttributeList(syntax) + ")");
      if ((is_target && has_target) || (is_intensity && has_intensity))
        Fail(attribute_at, "the attribute '" + attribute + "' repeated in <" + name + ">");
      const std::string value = ReadValue(name, attribute, start);
      if (is_target) {
        CheckTargetName(value, attribute, name, attribute_at);
        tag.target = value;
        has_target = true;
      } else {
        tag.intensity = ParseIntensity(value, name, attribute_at);
        has_intensity = true;
      }
    }
    if (!has_target) Fail(start, "the tag <" + name + "> without its " + std::string(syntax.target_attribute) + "=\"...\"");
    tag.word = WordOfTag(start);
    line_.tags.push_back(std::move(tag));
  }

  // ="value" or ='value', spaces allowed around '='.
  std::string ReadValue(const std::string& tag, const std::string& attribute, std::size_t tag_start) {
    SkipSpaces();
    if (AtEnd() || Peek() != '=') Fail(pos_, "the attribute '" + attribute + "' of <" + tag + "> without =\"value\"");
    ++pos_;
    SkipSpaces();
    if (AtEnd() || (Peek() != '"' && Peek() != '\''))
      Fail(pos_, "the value of '" + attribute + "' in <" + tag + "> not in quotes");
    const char quote = Peek();
    const std::size_t begin = ++pos_;
    const std::size_t close = markup_.find(quote, begin);
    if (close == std::string_view::npos) Fail(tag_start, "the tag <" + tag + "> is not closed (a quote is open)");
    pos_ = close + 1;
    return std::string(markup_.substr(begin, close - begin));
  }

  void CheckTargetName(const std::string& value, const std::string& attribute, const std::string& tag,
                       std::size_t at) const {
    bool is_name = !value.empty() && value.size() <= kMaxNameBytes;
    for (const char c : value) is_name = is_name && IsNameChar(c);
    if (!is_name)
      Fail(at, "the " + attribute + " of <" + tag + "> is not a name (1 to " + std::to_string(kMaxNameBytes) +
                   " letters, digits, '_' or '-')");
  }

  double ParseIntensity(const std::string& value, const std::string& tag, std::size_t at) const {
    double intensity = 0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), intensity);
    if (error != std::errc() || end != value.data() + value.size() || !std::isfinite(intensity))
      Fail(at, "the intensity \"" + value + "\" of <" + tag + "> is not a number");
    if (intensity < 0.0 || intensity > 1.0)
      Fail(at, "the intensity " + value + " of <" + tag + "> is outside [0, 1]");
    return intensity;
  }

  // The word the tag at `start` stands before: the next word to begin. A tag with a word's
  // letters right before and right after it stands inside that word.
  std::size_t WordOfTag(std::size_t start) const {
    const bool after_letters = !line_.text.empty() && !IsSpace(line_.text.back());
    const bool before_letters = !AtEnd() && !IsSpace(Peek()) && Peek() != '<';
    if (after_letters && before_letters) Fail(start, "a tag inside the word \"" + line_.words.back() + "...\"");
    return line_.words.size();
  }

  std::string_view markup_;
  std::string_view origin_;
  std::size_t pos_ = 0;
  MarkedLine line_;
};

// Flite's token name: the word without the punctuation its tokenizer takes off each end
// (cst_tokenstream's default pre- and post-punctuation).
std::string_view FliteTokenName(std::string_view word) {
  constexpr std::string_view kPrePunctuation = "\"'`({[";
  constexpr std::string_view kPostPunctuation = "\"'`.,:;!?(){}[]";
  const std::size_t first = word.find_first_not_of(kPrePunctuation);
  if (first == std::string_view::npos) return {};
  word.remove_prefix(first);
  const std::size_t last = word.find_last_not_of(kPostPunctuation);
  return last == std::string_view::npos ? std::string_view{} : word.substr(0, last + 1);
}

double LineEnd(const SpokenLine& spoken) {
  return spoken.phones.empty() ? spoken.DurationSeconds() : spoken.phones.back().end_s;
}

// Each word's start: its Flite token's first phone; a word of punctuation alone, or one Flite
// says nothing for, takes the next spoken word's start (the line's end after the last).
std::vector<double> WordStarts(const MarkedLine& line, const SpokenLine& spoken, std::string_view origin) {
  std::vector<std::optional<double>> own(line.words.size());
  std::size_t next_token = 0;
  for (std::size_t w = 0; w < line.words.size(); ++w) {
    const std::string_view name = FliteTokenName(line.words[w]);
    if (name.empty()) continue;
    std::size_t t = next_token;
    while (t < spoken.tokens.size() && spoken.tokens[t].name != name) ++t;
    if (t == spoken.tokens.size())
      throw SpeechError(std::string(origin) + ": the word \"" + line.words[w] + "\" (word " + std::to_string(w + 1) +
                        ") is not among the tokens the synthesizer read");
    own[w] = spoken.tokens[t].start_s;
    next_token = t + 1;
  }
  std::vector<double> starts(line.words.size());
  double next_start = LineEnd(spoken);
  for (std::size_t w = line.words.size(); w-- > 0;) {
    if (own[w]) next_start = *own[w];
    starts[w] = next_start;
  }
  return starts;
}

}  // namespace

MarkedLine ParseMarkup(std::string_view markup, std::string_view origin) { return Parser(markup, origin).Run(); }

std::vector<TimedTag> TimeTags(const MarkedLine& line, const SpokenLine& spoken, std::string_view origin) {
  const std::vector<double> starts = WordStarts(line, spoken, origin);
  std::vector<TimedTag> timed;
  timed.reserve(line.tags.size());
  for (const MarkupTag& tag : line.tags)
    timed.push_back({tag, tag.word < starts.size() ? starts[tag.word] : LineEnd(spoken)});
  return timed;
}

}  // namespace arview::speech
