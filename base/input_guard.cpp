#include "base/input_guard.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <vector>

namespace arview {

namespace fs = std::filesystem;

namespace {


std::string Bytes(std::uintmax_t n) {
  std::ostringstream ss;
  if (n >= (1ull << 30)) ss << (n >> 30) << " GiB";
  else if (n >= (1ull << 20)) ss << (n >> 20) << " MiB";
  else if (n >= (1ull << 10)) ss << (n >> 10) << " KiB";
  else ss << n << " bytes";
  return ss.str();
}

void RequireRegularMode(const fs::path& file, const struct stat& st) {
  if (!S_ISREG(st.st_mode)) throw InputError(file.string() + ": is " + FileKindOf(st.st_mode) + ", not a data file");
}

void RequireSizeAtMost(const fs::path& file, std::uintmax_t size, std::uintmax_t max_bytes) {
  if (size > max_bytes) {
    throw InputError(file.string() + ": " + Bytes(size) + " is larger than the " + Bytes(max_bytes) +
                     " such a file may have");
  }
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::uintmax_t RequireRegularFile(const fs::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) {
    const int err = errno;
    throw InputError(file.string() + ": " + (err == ENOENT ? "does not exist" : std::strerror(err)));
  }
  RequireRegularMode(file, st);
  return static_cast<std::uintmax_t>(st.st_size);
}

std::uintmax_t RequireRegularFileUpTo(const fs::path& file, std::uintmax_t max_bytes) {
  const std::uintmax_t size = RequireRegularFile(file);
  RequireSizeAtMost(file, size, max_bytes);
  return size;
}

std::string ReadFileUpTo(const fs::path& file, std::uintmax_t max_bytes, const CancellationToken& cancel) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused right after.
  Fd in{::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)};
  if (in.fd < 0) {
    const int err = errno;
    throw InputError(file.string() + ": " + (err == ENOENT ? "does not exist" : "cannot open (" +
                                                                                   std::string(std::strerror(err)) + ")"));
  }
  struct stat st {};
  if (::fstat(in.fd, &st) != 0) throw InputError(file.string() + ": cannot stat (" + std::strerror(errno) + ")");
  RequireRegularMode(file, st);
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  RequireSizeAtMost(file, size, max_bytes);
  ::fcntl(in.fd, F_SETFL, ::fcntl(in.fd, F_GETFL) & ~O_NONBLOCK);

  std::string data(static_cast<size_t>(size), '\0');
  size_t got = 0;
  constexpr size_t kChunk = 4u << 20;
  while (got < data.size()) {
    cancel.ThrowIfCancelled("stopped reading " + file.string());
    const ssize_t n = ::read(in.fd, data.data() + got, std::min(kChunk, data.size() - got));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw InputError(file.string() + ": read error (" + std::strerror(errno) + ")");
    if (n == 0) throw InputError(file.string() + ": shrank while being read (" + std::to_string(got) + " of " +
                                 std::to_string(size) + " bytes)");
    got += static_cast<size_t>(n);
  }
  char extra;
  ssize_t n;
  while ((n = ::read(in.fd, &extra, 1)) < 0 && errno == EINTR) {
  }
  if (n > 0) throw InputError(file.string() + ": grew while being read");
  return data;
}

int YamlNestingDepth(std::string_view text) {
  std::vector<size_t> indents;  // block indentation levels open at the current line
  int flow = 0;                 // [ and { open (they may span lines)
  int deepest = 0;
  char quote = 0;  // inside a quoted scalar: its quote character
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    size_t i = 0;
    int line_depth = 0;
    if (flow == 0 && quote == 0) {
      while (i < line.size() && line[i] == ' ') ++i;
      if (i == line.size() || line[i] == '#' || line[i] == '\r') continue;
      while (!indents.empty() && indents.back() > i) indents.pop_back();
      if (indents.empty() || indents.back() < i) indents.push_back(i);
      int dashes = 0;  // "- - - x": one sequence per dash on the same line
      while (i < line.size() && line[i] == '-' && (i + 1 == line.size() || line[i + 1] == ' ')) {
        ++dashes;
        ++i;
        while (i < line.size() && line[i] == ' ') ++i;
      }
      line_depth = static_cast<int>(indents.size()) + dashes;
    } else {
      line_depth = static_cast<int>(indents.size());
    }
    deepest = std::max(deepest, line_depth + flow);
    char previous = ' ';
    for (; i < line.size(); ++i) {
      const char c = line[i];
      if (quote != 0) {
        if (quote == '"' && c == '\\') ++i;
        else if (c == quote) quote = 0;
        previous = 'x';
        continue;
      }
      if (c == '#' && (previous == ' ' || previous == '\t')) break;
      // A quote opens a quoted scalar only where a scalar may start (it is plain text inside "it's").
      const bool scalar_start = previous == ' ' || previous == '\t' || previous == ':' || previous == ',' ||
                                previous == '[' || previous == '{' || previous == '-' || previous == '?';
      if ((c == '"' || c == '\'') && scalar_start) {
        quote = c;
      } else if (c == '[' || c == '{') {
        ++flow;
        deepest = std::max(deepest, line_depth + flow);
      } else if ((c == ']' || c == '}') && flow > 0) {
        --flow;
      }
      previous = c;
    }
    if (flow == 0 && quote == '\'') quote = 0;  // block context: single-line view of quotes is enough
    if (deepest > 1000000) break;
  }
  return deepest;
}

void RequireYamlDepthAtMost(std::string_view text, int max_depth, const std::string& name) {
  const int depth = YamlNestingDepth(text);
  if (depth > max_depth) {
    throw InputError(name + ": nested " + std::to_string(depth) + " levels deep (at most " +
                     std::to_string(max_depth) + " allowed)");
  }
}

namespace {

// At most 40 bytes of a line, for a message: bytes outside printable ASCII written \xNN.
std::string Excerpt(std::string_view line) {
  return PrintableForMessage(line.substr(0, 40), 40 * 4);  // every byte fits, escaped
}

}  // namespace

void RequireOpenCvYamlShape(std::string_view text, int max_depth, const std::string& name) {
  const size_t start = text.find_first_not_of(" \t\r\n");
  if (start == std::string_view::npos || text.substr(start, 5) != "%YAML") {
    throw InputError(name + ": is not OpenCV FileStorage YAML (it must begin with %YAML:1.0)");
  }
  RequireYamlDepthAtMost(text, max_depth, name);
  long long rows = -1;
  bool top_level_seen = false;
  int number = 0;
  for (size_t begin = 0; begin < text.size(); ++number) {
    size_t end = text.find('\n', begin);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(begin, end - begin);
    begin = end + 1;
    auto fail = [&](const std::string& problem) {
      throw InputError(name + ": line " + std::to_string(number + 1) + ": " + problem);
    };
    if (line.substr(0, 3) == "---") {
      const size_t after = line.find_first_not_of(" \t\r", 3);
      if (after != std::string_view::npos && !(after > 3 && line[after] == '#')) {
        fail("'" + Excerpt(line) + "' is not the document marker '---'");
      }
      continue;
    }
    if (line.substr(0, 3) == "...") {
      // The document's end: what follows starts a new top level, held to the same shape ("...",
      // then an indented "   - 1." loops forever too; found by fuzz_room_light). Text after the
      // marker on its own line, other than a comment, is refused: "...   - 0." kept OpenCV's
      // reader busy for over 10 s (fuzz_room_light in CI, 2026-12-05).
      const size_t after = line.find_first_not_of(" \t\r", 3);
      if (after != std::string_view::npos && line[after] != '#') {
        fail("'" + Excerpt(line) + "' is not the document end marker '...'");
      }
      top_level_seen = false;
      continue;
    }
    const size_t key = line.find_first_not_of(' ');
    const size_t content = line.find_first_not_of(" \t\r");
    if (content == std::string_view::npos || line[content] == '#' || line[0] == '%') continue;
    if (!top_level_seen) {
      top_level_seen = true;
      if (content != 0 || line[0] == '-') fail("'" + Excerpt(line) + "': the top level must be a mapping, its keys at the start of the line");
    }
    if (key == std::string_view::npos) continue;
    const std::string_view rest = line.substr(key);
    const bool is_rows = rest.substr(0, 5) == "rows:", is_cols = rest.substr(0, 5) == "cols:";
    if (!is_rows && !is_cols) continue;
    std::string_view value = rest.substr(5);
    value.remove_prefix(std::min(value.size(), value.find_first_not_of(" \t")));
    value = value.substr(0, value.find_last_not_of(" \t\r") + 1);
    if (value.empty() || value.size() > 9 || value.find_first_not_of("0123456789") != std::string_view::npos) {
      fail(std::string(is_rows ? "matrix rows" : "matrix cols") + " '" + Excerpt(value.substr(0, 20)) + "' is not a whole number");
    }
    const long long count = std::stoll(std::string(value));
    if (is_rows) {
      rows = count;
    } else if (rows >= 0 && rows * count > static_cast<long long>(text.size())) {
      fail("a matrix of " + std::to_string(rows) + " x " + std::to_string(count) +
           " values is larger than the file could hold");
    }
  }
}

std::optional<DuplicateKey> FindDuplicateYamlKey(std::string_view text) {
  struct Level {
    size_t indent;
    std::vector<std::pair<std::string, int>> keys;  // key, line
  };
  std::vector<Level> levels;
  int line_number = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    size_t i = line.find_first_not_of(' ');
    if (i == std::string_view::npos || line[i] == '#' || line[i] == '%' || line.substr(i, 3) == "---") continue;
    // A sequence item starts a new mapping one level deeper.
    while (i + 1 < line.size() && line[i] == '-' && line[i + 1] == ' ') {
      while (!levels.empty() && levels.back().indent >= i + 1) levels.pop_back();
      i = line.find_first_not_of(' ', i + 1);
      if (i == std::string_view::npos) break;
      levels.push_back({i, {}});
    }
    if (i == std::string_view::npos) continue;
    const char first = line[i];
    if (first == '"' || first == '\'' || first == '{' || first == '[' || first == '|' || first == '>') continue;
    const size_t colon = line.find(':', i);
    if (colon == std::string_view::npos || (colon + 1 < line.size() && line[colon + 1] != ' ')) continue;
    std::string key(line.substr(i, colon - i));
    while (!key.empty() && key.back() == ' ') key.pop_back();
    while (!levels.empty() && levels.back().indent > i) levels.pop_back();
    if (levels.empty() || levels.back().indent < i) levels.push_back({i, {}});
    for (const auto& [seen, seen_line] : levels.back().keys) {
      if (seen == key) return DuplicateKey{key, line_number, seen_line};
    }
    levels.back().keys.emplace_back(key, line_number);
  }
  return std::nullopt;
}

double RequireFiniteInRange(double value, double lo, double hi, const std::string& what) {
  if (!std::isfinite(value)) {
    std::ostringstream ss;
    ss << what << ": " << value << " is not a finite number";
    throw InputError(ss.str());
  }
  if (value < lo || value > hi) {
    std::ostringstream ss;
    ss << what << ": " << value << " is outside [" << lo << ", " << hi << "]";
    throw InputError(ss.str());
  }
  return value;
}

fs::path ResolveInside(const fs::path& folder, const fs::path& relative, const std::string& source) {
  std::error_code ec;
  const fs::path root = fs::weakly_canonical(fs::absolute(folder), ec);
  if (ec) throw InputError(folder.string() + ": cannot resolve (" + ec.message() + ")");
  const fs::path candidate = relative.is_absolute() ? relative : root / relative;
  const fs::path resolved = fs::weakly_canonical(candidate, ec);
  if (ec) throw InputError(source + ": cannot resolve '" + relative.string() + "' (" + ec.message() + ")");
  auto r = root.begin();
  auto p = resolved.begin();
  for (; r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == resolved.end() || *p != *r) {
      throw InputError(source + ": '" + relative.string() + "' points outside " + folder.string() +
                       " (refused: paths in a data file must stay inside its folder)");
    }
  }
  return resolved;
}

std::string PrintableForMessage(std::string_view text, size_t max_chars) {
  std::string out;
  for (const char c : text) {
    if (out.size() >= max_chars) return out + "...";
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f && byte != '\\') {
      out += c;
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out += escaped;
    }
  }
  return out;
}

std::string FileKindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace arview
