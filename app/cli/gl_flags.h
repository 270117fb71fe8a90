#pragma once
// The OpenGL flags of every command that renders (run, replay, demo, view, render, synth room):
// which renderer (--gl, --gl-device or ARVIEW_GL_DEVICE), llvmpipe's threads, and --verbose to
// see each renderer `--gl auto` passed over and why (render/gl_selection.h).

#include <CLI/CLI.hpp>

#include <string>

#include "render/offscreen.h"

namespace arview::app {

struct GlFlags {
  explicit GlFlags(int default_threads = 1) : threads(default_threads) {}
  std::string backend = "auto";
  int threads;       // llvmpipe's: the command's default
  int device = -1;   // --gl-device; -1: not given
  bool verbose = false;
};

void AddGlFlags(CLI::App* cmd, GlFlags& flags);
// Throws render::RenderError on a bad --gl value, CommandError (OffscreenOptions::Check under the
// flags' names, usage status 2) on --gl-device with --gl osmesa or egl (which use no EGL device).
render::OffscreenOptions ToOffscreenOptions(const GlFlags& flags);

}  // namespace arview::app
