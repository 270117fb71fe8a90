#pragma once
// A progress line for long work. On a terminal it redraws one line in place; when stderr is a
// file or pipe (CI, logs) it prints a line only at each further 10% so logs stay readable.

#include <unistd.h>

#include <cstdio>
#include <string>

namespace arview {

// The process's resident memory (/proc/self/statm), in MiB; -1 when it cannot be read.
inline double ResidentMemoryMiB() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return -1;
  long size = 0, resident = 0;
  const int n = std::fscanf(f, "%ld %ld", &size, &resident);
  std::fclose(f);
  if (n != 2) return -1;
  return static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1 << 20);
}

class Progress {
 public:
  explicit Progress(std::string label) : label_(std::move(label)), tty_(::isatty(STDERR_FILENO) == 1) {}
  ~Progress() { Finish(); }

  // `detail` is appended after the count, e.g. "12.3 fps".
  void Update(long done, long total, const std::string& detail = "") {
    if (total <= 0) return;
    const int percent = static_cast<int>(100 * done / total);
    if (tty_) {
      std::fprintf(stderr, "\r%s: %ld/%ld (%d%%) %s\033[K", label_.c_str(), done, total, percent, detail.c_str());
      std::fflush(stderr);
      open_ = true;
    } else if (percent / 10 > last_decile_ || done == total) {
      last_decile_ = percent / 10;
      std::fprintf(stderr, "%s: %ld/%ld (%d%%) %s\n", label_.c_str(), done, total, percent, detail.c_str());
    }
  }

  void Finish() {
    if (open_) std::fprintf(stderr, "\n");
    open_ = false;
  }

 private:
  std::string label_;
  bool tty_;
  bool open_ = false;
  int last_decile_ = -1;
};

}  // namespace arview
