#pragma once
// What `arview map` and `arview map extend` show on the terminal while COLMAP runs: one progress
// line per stage with the time taken and left, notes and the self-check's warnings.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

#include "base/cancellation.h"
#include "mapping/colmap_pipeline.h"

namespace arview::app {

// "1:05" for 65 seconds.
inline std::string MinutesSeconds(double seconds) {
  const long whole = std::lround(std::max(0.0, seconds));
  std::ostringstream s;
  s << whole / 60 << ":" << std::setw(2) << std::setfill('0') << whole % 60;
  return s.str();
}

// One progress line per stage on stderr: redrawn in place on a terminal, printed at every
// 25% otherwise (logs stay short). Once a stage has run a few seconds, the line says how long it
// has taken and how long the rest will take at the rate so far ("about 1:05 left": COLMAP's
// stages are long, and a user wants to know whether to wait).
class ProgressBar {
 public:
  ProgressBar() : tty_(::isatty(STDERR_FILENO) != 0) {}
  ~ProgressBar() { Finish(); }
  void Update(const std::string& stage, int done, int total) {
    if (stage != stage_) {
      Finish();
      stage_ = stage;
      last_quarter_ = -1;
      started_ = std::chrono::steady_clock::now();
    }
    if (tty_) {
      const int width = 30;
      const int filled = total > 0 ? std::min(width, done * width / total) : 0;
      std::cerr << "\r" << std::left << std::setw(8) << stage << " [" << std::string(static_cast<size_t>(filled), '#')
                << std::string(static_cast<size_t>(width - filled), ' ') << "] " << done << "/" << total
                << TimeLeft(done, total) << "   " << std::flush;
      open_ = true;
    } else if (total > 0) {
      const int quarter = done * 4 / total;
      if (quarter != last_quarter_) {
        std::cerr << stage << ": " << done << "/" << total << TimeLeft(done, total) << "\n";
        last_quarter_ = quarter;
      }
    }
  }
  void Finish() {
    if (open_) std::cerr << "\n";
    open_ = false;
  }

 private:
  // ", 0:41, about 1:05 left"; nothing in a stage's first seconds or without a count.
  std::string TimeLeft(int done, int total) const {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    if (elapsed < 3 || done <= 0 || total <= 0) return "";
    if (done >= total) return ", " + MinutesSeconds(elapsed);
    return ", " + MinutesSeconds(elapsed) + ", about " + MinutesSeconds(elapsed * (total - done) / done) + " left";
  }

  bool tty_;
  bool open_ = false;
  std::string stage_;
  int last_quarter_ = -1;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

// Progress on `bar` (nothing more after a Ctrl-C: only the line saying what stopped), notes and
// warnings each on a line of their own on stderr.
inline mapping::MapBuildCallbacks ConsoleCallbacks(ProgressBar& bar, const CancellationToken& cancel) {
  mapping::MapBuildCallbacks callbacks;
  callbacks.progress = [&bar, cancel](const std::string& stage, int done, int total) {
    if (!cancel.IsCancelled()) bar.Update(stage, done, total);
  };
  callbacks.note = [&bar](const std::string& message) {
    bar.Finish();
    std::cerr << "note: " << message << "\n";
  };
  callbacks.warning = [&bar](const std::string& message) {
    bar.Finish();
    std::cerr << "warning: the map " << message << "\n";
  };
  return callbacks;
}

}  // namespace arview::app
