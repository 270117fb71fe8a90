#pragma once
// The window of `arview view`, `arview run` and `arview replay`: plain Xlib, frames blitted with
// the MIT shared-memory extension (XShmPutImage; XPutImage where the server is remote). The
// frames are rendered offscreen (OSMesa/llvmpipe, or EGL) and read back anyway, so a GL window
// would only add a second copy; docs/anim.md has the measured frame rates. Mouse and keys come
// back as plain events.
//
// Xlib is used without XInitThreads: a window must be used by one thread at a time. The live
// pipeline opens it on the main thread (so that a missing display is said before anything
// loads) and from then on only its sink thread shows frames and reads events, until the
// threads are joined.

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace arview::video {

struct InputEvent {
  enum class Type { kPress, kRelease, kMotion, kKey, kClose };
  Type type = Type::kMotion;
  int x = 0, y = 0;  // pointer, window pixels
  int button = 0;    // kPress/kRelease: 1 left, 2 middle, 3 right, 4/5 wheel up/down
  bool shift = false, control = false;
  std::string key;   // kKey: the X keysym name ("a", "s", "bracketright", "Delete", "Escape", "F1", ...)
};

// Where the window opens.
struct WindowPlacement {
  // A RandR output's name ("HDMI-1", "DP-2"; Xvfb's is "screen"): the window opens at its
  // top-left corner, e.g. on a headset's panel. Empty: where the window manager puts it.
  std::string output;
  // Asks the window manager for fullscreen (EWMH _NET_WM_STATE_FULLSCREEN), on `output` if given.
  bool fullscreen = false;
};

// A connected output of the display with its area on the root window.
struct DisplayOutput {
  std::string name;
  cv::Rect area;
};

class DisplayWindow {
 public:
  // Opens a window of `size` on $DISPLAY. Throws VideoError with one line when there is no
  // display (DISPLAY unset, or the server refuses) or its visual is not 24-bit true colour;
  // `without_display` ends that line (what to do instead, e.g. "write to a file with --out").
  // An unknown `placement.output` is a VideoError listing the connected ones.
  static std::unique_ptr<DisplayWindow> Open(const std::string& title, cv::Size size, const std::string& without_display,
                                             const WindowPlacement& placement = {});
  virtual ~DisplayWindow() = default;

  // Shows an 8-bit BGR frame of the window's size.
  virtual void Show(const cv::Mat& bgr) = 0;
  // Events since the last call (never blocks). An exposed window is repainted with the last
  // frame shown, so that a window uncovered while no frame comes (a stalled camera) is not blank.
  virtual std::vector<InputEvent> Poll() = 0;
  virtual void SetTitle(const std::string& title) = 0;
  // "MIT-SHM" or "XPutImage".
  virtual std::string PresentMethod() const = 0;
  virtual cv::Size size() const = 0;
  // "at HDMI-1 (2560x1440+1920+0), fullscreen", or "" without a placement.
  virtual std::string PlacementText() const = 0;
};

}  // namespace arview::video
