// arview demo: the command line of the demo (app/demo/demo.h runs its steps).

#include <memory>
#include <string>

#include "app/cli/commands.h"
#include "app/cli/gl_flags.h"
#include "app/cli/numeric_flags.h"
#include "app/demo/demo.h"

namespace arview::app {

namespace {

struct DemoArgs {
  DemoOptions demo;
  std::string size = "640x480";  // --size, parsed into demo.frame_width/height
  GlFlags gl;                     // into demo.gl
};

}  // namespace

void AddDemoCommand(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  auto* cmd = app.add_subcommand("demo", "Run everything on the embedded default scene (no camera, no downloads)");
  cmd->add_option("--out", a->demo.out, "The augmented video (default: <work>/demo.mp4)");
  cmd->add_option("--work", a->demo.work, "Folder for the recordings, the map and the reports (reused by a re-run)")
      ->capture_default_str();
  cmd->add_option("--frames", a->demo.frames, "Frames of the walk through the room (30 fps); the first half is mapped")
      ->capture_default_str()
      ->check(CLI::Range(60, 6000));
  cmd->add_option("--map-every", a->demo.map_every, "Map from every N-th frame of the first half")
      ->capture_default_str()
      ->check(CLI::Range(1, 30));
  cmd->add_option("--character", a->demo.character,
                  "Character asset: builtin:figure (the project's humanoid), a file such as "
                  "/usr/share/assimp/models/X/BCN_Epileptic.X, or the Fox .glb")
      ->capture_default_str();
  cmd->add_option("--height", a->demo.height, "Character height in metres")->capture_default_str()->check(CLI::Range(0.1, 5.0));
  AddGlFlags(cmd, a->gl);
  cmd->add_option("--size", a->size,
                  "Frame size WxH of the walk (the room is rendered, mapped and replayed at it; field of view kept), "
                  "e.g. 1280x720; use a --work folder of its own per size, or the walk and map are made again")
      ->capture_default_str()
      ->check(FrameSizeCheck({160, 120}, {3840, 2160}));
  cmd->add_option("--aa", a->demo.aa, "Antialiasing of the character: msaa (4x multisampling) or none (cheaper on a CPU renderer)")
      ->capture_default_str()
      ->check(CLI::IsMember({"msaa", "none"}));
  cmd->add_flag("--hmd", a->demo.hmd, "Side-by-side stereo output");
  cmd->add_flag("--no-hud", a->demo.no_hud,
                "No overlay (by default the video shows the view sphere with the keys and the current viewpoint, "
                "the weights, the tracking status and the frame rate)");
  cmd->add_option("--greet-within", a->demo.greet_within,
                  "The character greets (its Wave clip, once) when the viewer comes within this many metres; 0: never")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  cmd->callback([a] {
    const cv::Size size = *ParseFrameSize(a->size);  // checked by --size's validator
    a->demo.frame_width = size.width;
    a->demo.frame_height = size.height;
    a->demo.gl = ToOffscreenOptions(a->gl);
    RunDemo(a->demo);
  });
}

}  // namespace arview::app
