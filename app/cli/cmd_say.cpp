// arview say --scene scene.yaml "text" [--character NAME] [--voice slt|rms|awb] [--out say.mp4]
//            [--curves curves.json] [--size WxH] [--fps N]
// A close-up video of a scene's character saying a line, for authoring lines (docs/speech.md).

#include <cstdio>

#include "app/cli/commands.h"
#include "app/cli/gl_flags.h"
#include "app/cli/numeric_flags.h"
#include "app/cli/output_flags.h"
#include "app/session/say_video.h"

namespace arview::app {

namespace {

struct SayArgs {
  std::string scene, text, character, voice, out = "say.mp4", curves, size = "640x480";
  double fps = 30, distance = 0.6;
  GlFlags gl;
};

void RunSay(const SayArgs& a) {
  RequireDistinctOutputs({{"--out", a.out}, {"--curves", a.curves}});
  SayOptions o;
  o.scene = a.scene;
  o.character = a.character;
  o.text = a.text;
  o.voice = a.voice;
  o.out = a.out;
  o.curves = a.curves;
  o.size = *ParseFrameSize(a.size);  // checked by --size's validator
  o.fps = a.fps;
  o.distance = a.distance;
  o.gl = ToOffscreenOptions(a.gl);
  const SayResult r = RenderSpokenLine(o);
  std::printf("wrote %s: %d frames (%.2f s at %g fps), the line %.2f s of %s's speech at 16 kHz%s%s\nrenderer: %s\n",
              a.out.c_str(), r.frames, r.frames / a.fps, a.fps, r.utterance.line->DurationSeconds(), r.utterance.character.c_str(),
              a.curves.empty() ? "" : "; curves in ", a.curves.c_str(), r.renderer.c_str());
}

}  // namespace

void AddSayCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("say", "Render a close-up video of a scene's character saying a line (authoring lines)");
  auto a = std::make_shared<SayArgs>();
  cmd->add_option("text", a->text,
                  "What to say, with the markup of docs/speech.md: <gesture name=\"Wave\"/>, "
                  "<face expr=\"happy\" intensity=\"0.6\"/>, <gaze at=\"viewer\"/>")
      ->required();
  cmd->add_option("--scene", a->scene, "Scene file (YAML, docs/anim.md)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--character", a->character, "The scene's character who speaks, by name (default: the first)");
  cmd->add_option("--voice", a->voice, "Flite's voice: slt, rms or awb (default: the character's voice:, else slt)");
  cmd->add_option("--out", a->out, "Video file (.mp4, .mkv, .avi) or a folder for PNG frames")->default_val(a->out);
  cmd->add_option("--curves", a->curves,
                  "Also write JSON: per frame the talking weight, the mouth's opening, the lip seal and the 15 viseme "
                  "weights, and the line's sample count and FNV-1a hash")
      ->check(OutputFileCheck());
  cmd->add_option("--size", a->size, "Video size")->default_val(a->size)->check(FrameSizeCheck({64, 64}, {7680, 4320}));
  cmd->add_option("--fps", a->fps, "Frames per second")->default_val(a->fps)->check(CLI::Range(1.0, 120.0));
  cmd->add_option("--distance", a->distance, "The camera's distance in front of the head, map units")
      ->default_val(a->distance)
      ->check(CLI::Range(0.2, 10.0));
  AddGlFlags(cmd, a->gl);
  cmd->callback([a] { RunSay(*a); });
}

}  // namespace arview::app
