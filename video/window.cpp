#include "video/window.h"

#include <X11/Xlib.h>
#include <X11/Xatom.h>
#include <X11/Xutil.h>
#include <X11/extensions/XShm.h>
#include <X11/extensions/Xrandr.h>
#include <sys/ipc.h>
#include <sys/shm.h>

#include <opencv2/imgproc.hpp>

#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "video/video_error.h"

namespace arview::video {

namespace {

// Xlib reports errors through a callback that exits by default; a failed XShmAttach (a remote
// server) must instead fall back to XPutImage.
bool g_x_error = false;
int RecordXError(Display*, XErrorEvent*) {
  g_x_error = true;
  return 0;
}

std::string AreaText(const cv::Rect& r) {
  return std::to_string(r.width) + "x" + std::to_string(r.height) + "+" + std::to_string(r.x) + "+" + std::to_string(r.y);
}

// The connected outputs that show part of the screen (a CRTC drives them).
std::vector<DisplayOutput> ConnectedOutputs(Display* display) {
  std::vector<DisplayOutput> outputs;
  int event_base = 0, error_base = 0;
  if (!XRRQueryExtension(display, &event_base, &error_base)) return outputs;
  XRRScreenResources* resources = XRRGetScreenResourcesCurrent(display, DefaultRootWindow(display));
  if (!resources) return outputs;
  for (int i = 0; i < resources->noutput; ++i) {
    XRROutputInfo* output = XRRGetOutputInfo(display, resources, resources->outputs[i]);
    if (!output) continue;
    if (output->connection == RR_Connected && output->crtc) {
      if (XRRCrtcInfo* crtc = XRRGetCrtcInfo(display, resources, output->crtc)) {
        outputs.push_back({std::string(output->name, static_cast<size_t>(output->nameLen)),
                           cv::Rect(crtc->x, crtc->y, static_cast<int>(crtc->width), static_cast<int>(crtc->height))});
        XRRFreeCrtcInfo(crtc);
      }
    }
    XRRFreeOutputInfo(output);
  }
  XRRFreeScreenResources(resources);
  return outputs;
}

class X11Window final : public DisplayWindow {
 public:
  X11Window(const std::string& title, cv::Size size, const std::string& without_display, const WindowPlacement& placement)
      : size_(size) {
    const char* name = std::getenv("DISPLAY");
    if (name == nullptr || *name == '\0') {
      throw VideoError("window: no display (DISPLAY is not set); " + without_display);
    }
    display_ = XOpenDisplay(name);
    if (!display_) throw VideoError(std::string("window: cannot open display '") + name + "'; " + without_display);
    const int screen = DefaultScreen(display_);
    Visual* visual = DefaultVisual(display_, screen);
    const int depth = DefaultDepth(display_, screen);
    if (depth != 24 || visual->red_mask != 0xff0000 || visual->green_mask != 0xff00 || visual->blue_mask != 0xff) {
      XCloseDisplay(display_);
      throw VideoError(std::string("window: display '") + name + "' has a " + std::to_string(depth) +
                  "-bit visual; a 24-bit true-colour display is needed");
    }
    cv::Point origin(0, 0);
    if (!placement.output.empty()) {
      const cv::Rect area = OutputArea(placement.output, name);
      origin = area.tl();
      placement_text_ = "at " + placement.output + " (" + AreaText(area) + ")";
    }
    window_ = XCreateSimpleWindow(display_, RootWindow(display_, screen), origin.x, origin.y, size.width, size.height, 0,
                                  BlackPixel(display_, screen), BlackPixel(display_, screen));
    XStoreName(display_, window_, title.c_str());
    // A fixed size: the renderer's camera has the window's size. The position is the user's
    // (USPosition): a window manager keeps it.
    XSizeHints hints{};
    hints.flags = PMinSize | PMaxSize | (placement.output.empty() ? 0 : USPosition | PPosition);
    hints.x = origin.x, hints.y = origin.y;
    hints.min_width = hints.max_width = size.width;
    hints.min_height = hints.max_height = size.height;
    XSetWMNormalHints(display_, window_, &hints);
    if (placement.fullscreen) {
      // Before mapping: an EWMH window manager then maps it fullscreen on the output it sits on.
      Atom state = XInternAtom(display_, "_NET_WM_STATE", False);
      Atom fullscreen = XInternAtom(display_, "_NET_WM_STATE_FULLSCREEN", False);
      XChangeProperty(display_, window_, state, XA_ATOM, 32, PropModeReplace, reinterpret_cast<unsigned char*>(&fullscreen), 1);
      placement_text_ += placement_text_.empty() ? "fullscreen" : ", fullscreen";
    }
    XSelectInput(display_, window_,
                 ExposureMask | KeyPressMask | ButtonPressMask | ButtonReleaseMask | PointerMotionMask |
                     StructureNotifyMask);
    wm_delete_ = XInternAtom(display_, "WM_DELETE_WINDOW", False);
    XSetWMProtocols(display_, window_, &wm_delete_, 1);
    gc_ = XCreateGC(display_, window_, 0, nullptr);
    CreateImage(visual, depth);
    XMapWindow(display_, window_);
    XFlush(display_);
  }

  ~X11Window() override {
    if (shm_image_) {
      XShmDetach(display_, &shm_);
      XDestroyImage(image_);
      shmdt(shm_.shmaddr);
    } else if (image_) {
      XDestroyImage(image_);  // frees pixels_ too
    }
    XFreeGC(display_, gc_);
    XDestroyWindow(display_, window_);
    XCloseDisplay(display_);
  }

  void Show(const cv::Mat& bgr) override {
    if (bgr.size() != size_ || bgr.type() != CV_8UC3) throw VideoError("window: frame does not fit the window");
    cv::Mat pixels(size_, CV_8UC4, image_->data, image_->bytes_per_line);
    cv::cvtColor(bgr, pixels, cv::COLOR_BGR2BGRA);
    shown_ = true;
    PutImage();
  }

  std::vector<InputEvent> Poll() override {
    std::vector<InputEvent> events;
    bool exposed = false;
    while (XPending(display_) > 0) {
      XEvent e;
      XNextEvent(display_, &e);
      exposed |= e.type == Expose;
      Translate(e, events);
    }
    if (exposed && shown_) PutImage();
    return events;
  }

  void SetTitle(const std::string& title) override {
    XStoreName(display_, window_, title.c_str());
    XFlush(display_);
  }

  std::string PresentMethod() const override { return shm_image_ ? "MIT-SHM" : "XPutImage"; }
  std::string PlacementText() const override { return placement_text_; }
  cv::Size size() const override { return size_; }

 private:
  // The area of the connected output `output`; an Error listing the outputs when there is none.
  cv::Rect OutputArea(const std::string& output, const char* display_name) {
    const std::vector<DisplayOutput> outputs = ConnectedOutputs(display_);
    std::string list;
    for (const DisplayOutput& o : outputs) {
      if (o.name == output) return o.area;
      list += (list.empty() ? "" : ", ") + o.name + " " + AreaText(o.area);
    }
    XCloseDisplay(display_);
    throw VideoError(std::string("window: display '") + display_name + "' has no connected output '" + output + "' (" +
                (list.empty() ? std::string("it reports none through RandR") : "connected: " + list) + ")");
  }

  void PutImage() {
    if (shm_image_) {
      XShmPutImage(display_, window_, gc_, image_, 0, 0, 0, 0, size_.width, size_.height, False);
    } else {
      XPutImage(display_, window_, gc_, image_, 0, 0, 0, 0, size_.width, size_.height);
    }
    // A round trip: the server has copied the shared buffer before the next frame overwrites
    // it, and a slow server paces the loop instead of queueing frames.
    XSync(display_, False);
  }

  void CreateImage(Visual* visual, int depth) {
    if (XShmQueryExtension(display_)) {
      image_ = XShmCreateImage(display_, visual, depth, ZPixmap, nullptr, &shm_, size_.width, size_.height);
      if (image_) {
        shm_.shmid = shmget(IPC_PRIVATE, static_cast<size_t>(image_->bytes_per_line) * image_->height, IPC_CREAT | 0600);
        shm_.shmaddr = image_->data = shm_.shmid >= 0 ? static_cast<char*>(shmat(shm_.shmid, nullptr, 0)) : nullptr;
        shm_.readOnly = False;
        bool attached = false;
        if (shm_.shmaddr != nullptr && shm_.shmaddr != reinterpret_cast<char*>(-1)) {
          g_x_error = false;
          XErrorHandler previous = XSetErrorHandler(RecordXError);
          attached = XShmAttach(display_, &shm_) && (XSync(display_, False), !g_x_error);
          XSetErrorHandler(previous);
        }
        if (shm_.shmid >= 0) shmctl(shm_.shmid, IPC_RMID, nullptr);  // freed when both sides detach
        if (attached) {
          shm_image_ = true;
        } else {
          if (shm_.shmaddr != nullptr && shm_.shmaddr != reinterpret_cast<char*>(-1)) shmdt(shm_.shmaddr);
          image_->data = nullptr;
          XDestroyImage(image_);
          image_ = nullptr;
        }
      }
    }
    if (!image_) {
      char* pixels = static_cast<char*>(std::malloc(static_cast<size_t>(size_.width) * size_.height * 4));
      image_ = XCreateImage(display_, visual, depth, ZPixmap, 0, pixels, size_.width, size_.height, 32, 0);
      if (!image_) throw VideoError("window: cannot create the window's image");
    }
    if (image_->bits_per_pixel != 32) throw VideoError("window: the display does not store 32-bit pixels");
  }

  void Translate(const XEvent& e, std::vector<InputEvent>& out) {
    InputEvent ev;
    switch (e.type) {
      case ButtonPress:
      case ButtonRelease:
        ev.type = e.type == ButtonPress ? InputEvent::Type::kPress : InputEvent::Type::kRelease;
        ev.x = e.xbutton.x, ev.y = e.xbutton.y, ev.button = static_cast<int>(e.xbutton.button);
        ev.shift = e.xbutton.state & ShiftMask, ev.control = e.xbutton.state & ControlMask;
        out.push_back(ev);
        break;
      case MotionNotify:
        ev.type = InputEvent::Type::kMotion;
        ev.x = e.xmotion.x, ev.y = e.xmotion.y;
        ev.shift = e.xmotion.state & ShiftMask, ev.control = e.xmotion.state & ControlMask;
        out.push_back(ev);
        break;
      case KeyPress: {
        XKeyEvent key = e.xkey;
        char text[8];
        KeySym sym = 0;
        XLookupString(&key, text, sizeof text, &sym, nullptr);
        const char* name = XKeysymToString(sym);
        if (!name) break;
        ev.type = InputEvent::Type::kKey;
        ev.key = name;
        ev.x = key.x, ev.y = key.y;
        ev.shift = key.state & ShiftMask, ev.control = key.state & ControlMask;
        out.push_back(ev);
        break;
      }
      case ClientMessage:
        if (static_cast<Atom>(e.xclient.data.l[0]) == wm_delete_) {
          ev.type = InputEvent::Type::kClose;
          out.push_back(ev);
        }
        break;
      case DestroyNotify:
        ev.type = InputEvent::Type::kClose;
        out.push_back(ev);
        break;
      default:
        break;
    }
  }

  cv::Size size_;
  Display* display_ = nullptr;
  Window window_ = 0;
  GC gc_ = nullptr;
  Atom wm_delete_ = 0;
  XImage* image_ = nullptr;
  XShmSegmentInfo shm_{};
  bool shm_image_ = false;
  bool shown_ = false;  // the image holds a frame (Expose repaints it)
  std::string placement_text_;
};

}  // namespace

std::unique_ptr<DisplayWindow> DisplayWindow::Open(const std::string& title, cv::Size size, const std::string& without_display,
                                                   const WindowPlacement& placement) {
  if (size.width <= 0 || size.height <= 0) throw VideoError("window: size must be positive");
  return std::make_unique<X11Window>(title, size, without_display, placement);
}

}  // namespace arview::video
