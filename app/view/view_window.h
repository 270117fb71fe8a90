#pragma once
// The window of `arview view`: plain Xlib, frames blitted with the MIT shared-memory extension
// (XShmPutImage; XPutImage where the server is remote). The frames are rendered offscreen
// (OSMesa/llvmpipe) and read back anyway, so a GL window would only add a second copy;
// docs/anim.md has the measured frame rates. Mouse and keys come back as plain events.

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace arview::app {

struct InputEvent {
  enum class Type { kPress, kRelease, kMotion, kKey, kClose };
  Type type = Type::kMotion;
  int x = 0, y = 0;  // pointer, window pixels
  int button = 0;    // kPress/kRelease: 1 left, 2 middle, 3 right, 4/5 wheel up/down
  bool shift = false, control = false;
  std::string key;   // kKey: the X keysym name ("a", "s", "bracketright", "Delete", "Escape", "F1", ...)
};

class ViewWindow {
 public:
  // Opens a window of `size` on $DISPLAY. Throws std::runtime_error with one line when there is
  // no display (DISPLAY unset, or the server refuses) or its visual is not 24-bit true colour.
  static std::unique_ptr<ViewWindow> Open(const std::string& title, cv::Size size);
  virtual ~ViewWindow() = default;

  // Shows an 8-bit BGR frame of the window's size.
  virtual void Show(const cv::Mat& bgr) = 0;
  // Events since the last call (never blocks).
  virtual std::vector<InputEvent> Poll() = 0;
  // "MIT-SHM" or "XPutImage".
  virtual std::string PresentMethod() const = 0;
  virtual cv::Size size() const = 0;
};

}  // namespace arview::app
