// An ALSA device unplugged mid-session, for the live sound and microphone tests: preloaded into
// `arview` (LD_PRELOAD), it passes snd_pcm_writei, snd_pcm_readi and snd_pcm_delay through to
// ALSA until ARVIEW_PCM_UNPLUG_AFTER_S seconds after the first of them on a stream of the
// direction ARVIEW_PCM_UNPLUG names (`playback` or `capture`), and from then on answers -ENODEV
// for that direction, as ALSA does for a USB card pulled out. The tests' emulated devices (ALSA's
// `file` plugin over `null`) cannot vanish on their own.
// Not instrumented and no arview library: it stands in for the kernel's driver.

#include <alsa/asoundlib.h>
#include <dlfcn.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>

namespace {

using Clock = std::chrono::steady_clock;

struct Unplug {
  snd_pcm_stream_t stream = SND_PCM_STREAM_PLAYBACK;
  double after_s = -1;  // < 0: never
};

const Unplug& Settings() {
  static const Unplug settings = [] {
    Unplug u;
    const char* direction = std::getenv("ARVIEW_PCM_UNPLUG");
    const char* after = std::getenv("ARVIEW_PCM_UNPLUG_AFTER_S");
    if (direction == nullptr || after == nullptr) return u;
    u.stream = std::strcmp(direction, "capture") == 0 ? SND_PCM_STREAM_CAPTURE : SND_PCM_STREAM_PLAYBACK;
    u.after_s = std::atof(after);
    return u;
  }();
  return settings;
}

// Whether the device of `pcm`'s direction is gone: the clock starts at the first call on it.
bool Gone(snd_pcm_t* pcm) {
  static std::atomic<Clock::rep> first{0};
  const Unplug& u = Settings();
  if (u.after_s < 0 || snd_pcm_stream(pcm) != u.stream) return false;
  const Clock::rep now = Clock::now().time_since_epoch().count();
  Clock::rep expected = 0;
  first.compare_exchange_strong(expected, now);
  const Clock::rep started = expected == 0 ? now : expected;
  return std::chrono::duration<double>(Clock::duration(now - started)).count() >= u.after_s;
}

template <typename F>
F Next(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
}

}  // namespace

extern "C" {

snd_pcm_sframes_t snd_pcm_writei(snd_pcm_t* pcm, const void* buffer, snd_pcm_uframes_t size) {
  static const auto next = Next<snd_pcm_sframes_t (*)(snd_pcm_t*, const void*, snd_pcm_uframes_t)>("snd_pcm_writei");
  return Gone(pcm) ? -ENODEV : next(pcm, buffer, size);
}

snd_pcm_sframes_t snd_pcm_readi(snd_pcm_t* pcm, void* buffer, snd_pcm_uframes_t size) {
  static const auto next = Next<snd_pcm_sframes_t (*)(snd_pcm_t*, void*, snd_pcm_uframes_t)>("snd_pcm_readi");
  return Gone(pcm) ? -ENODEV : next(pcm, buffer, size);
}

int snd_pcm_delay(snd_pcm_t* pcm, snd_pcm_sframes_t* delay) {
  static const auto next = Next<int (*)(snd_pcm_t*, snd_pcm_sframes_t*)>("snd_pcm_delay");
  return Gone(pcm) ? -ENODEV : next(pcm, delay);
}

}  // extern "C"
