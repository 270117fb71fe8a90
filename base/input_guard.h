#pragma once
// Guards at the edges: what every parser checks before it trusts a file or a number.
//
// - Only regular files are opened as data: a device (/dev/zero), a FIFO, a socket or a
//   directory - also behind a symlink - is refused before a byte is read (a FIFO is opened
//   non-blocking, so that refusing it cannot hang).
// - A size limit before reading: a file is read whole only when it is small enough, and a
//   file that grows while being read is refused.
// - Nesting depth of YAML measured on the text before any recursive parser sees it.
// - Numbers finite and in range (NaN and infinities never reach the maths).
// - Paths named inside data files resolved inside their folder, symlinks included.
// Every failure is an InputError whose what() is the one line for the user, naming the file
// or flag.

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "base/cancellation.h"
#include "base/error.h"

namespace arview {

class InputError : public Error {
 public:
  using Error::Error;
};

// Size limits for the files arview reads (generous for real data, far below a huge allocation).
inline constexpr std::uintmax_t kMaxTextFileBytes = 64ull << 20;     // frames.txt, trajectories, YAML
inline constexpr std::uintmax_t kMaxCameraFileBytes = 1ull << 20;    // camera.yaml
inline constexpr std::uintmax_t kMaxBinaryFileBytes = 8ull << 30;    // COLMAP models, map.arvmap
inline constexpr std::uintmax_t kMaxImageFileBytes = 256ull << 20;   // one PNG/JPEG frame
inline constexpr int kMaxYamlDepth = 64;

// Throws InputError unless `file` is (or links to) a regular file; returns its size.
std::uintmax_t RequireRegularFile(const std::filesystem::path& file);

// RequireRegularFile and a size of at most `max_bytes`; returns the size.
std::uintmax_t RequireRegularFileUpTo(const std::filesystem::path& file, std::uintmax_t max_bytes);

// The whole file, checked as above on the opened descriptor (no race with a swapped file),
// read in chunks with `cancel` looked at between them.
std::string ReadFileUpTo(const std::filesystem::path& file, std::uintmax_t max_bytes,
                         const CancellationToken& cancel = {});

// The deepest nesting of a YAML text: block indentation levels plus flow brackets, counted
// without parsing (quotes and comments skipped). An upper bound of what a parser would recurse.
int YamlNestingDepth(std::string_view text);

// Throws InputError("<name>: nested deeper than <max> levels") when the text is too deep.
void RequireYamlDepthAtMost(std::string_view text, int max_depth, const std::string& name);

// The checks OpenCV 4.6's FileStorage YAML reader lacks, for a text about to be handed to it
// (camera files, room light files). Throws InputError("<name>: ...", naming the line) when
//  - it does not begin with the %YAML header;
//  - it nests deeper than max_depth levels (the reader recurses);
//  - a line beginning "---" is not the document marker itself: "----x" after the header, then
//    two lines of text, sends the reader into an endless loop (found by fuzz_camera);
//  - the top level is not a mapping whose keys start the line: an indented first line ("   - 3")
//    followed by a less indented one loops forever too (found by fuzz_room_light), and so does
//    an indented line after a document end "..." (the same shape, found by fuzz_room_light again);
//  - a matrix's rows/cols is not a plain number, or rows x cols is more elements than the text
//    could hold: the reader allocates the matrix before reading its data (51-85 GB once).
void RequireOpenCvYamlShape(std::string_view text, int max_depth, const std::string& name);

// The first key given twice in one block mapping of a YAML text ("key" and its 1-based line),
// or nothing. Flow mappings ({a: 1, a: 2}) are not looked into: callers whose files use them
// check duplicates with their parser.
struct DuplicateKey {
  std::string key;
  int line = 0;
  int first_line = 0;
};
std::optional<DuplicateKey> FindDuplicateYamlKey(std::string_view text);

// `value` when finite and within [lo, hi]; else InputError("<what>: ... ").
double RequireFiniteInRange(double value, double lo, double hi, const std::string& what);
inline double RequireFinite(double value, const std::string& what) {
  return RequireFiniteInRange(value, -1e300, 1e300, what);
}

// The path `relative` (from a data file in `folder`) resolved with symlinks; InputError
// naming `source` unless it stays inside `folder`. Absolute paths must also be inside.
std::filesystem::path ResolveInside(const std::filesystem::path& folder, const std::filesystem::path& relative,
                                    const std::string& source);

// Text taken from a data file, made fit to quote in a one-line message: bytes outside printable
// ASCII as \xNN (a name holding a newline would split the line; binary would garble the
// terminal), cut to `max_chars` with "..." after.
std::string PrintableForMessage(std::string_view text, size_t max_chars = 120);

// What a file of this st_mode is, for messages: "a directory", "a character device", "a FIFO",
// "a socket", ... ("not a regular file" for any other non-regular kind).
std::string FileKindOf(mode_t mode);

}  // namespace arview
