#include "app/cli/audio_flags.h"

#include <cstdio>

#include "anim_authoring/scene.h"
#include "app/session/ar_session.h"
#include "audio/audio_error.h"

namespace arview::app {

void AddAudioOutFlag(CLI::App* cmd, std::string& value) {
  cmd->add_option("--audio-out", value,
                  "Where the character's speech is played: default (ALSA's default device), none, or an ALSA device "
                  "name (hw:1,0, plughw:CARD=USB,DEV=0); without a sound device the session goes on silent")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            try {
              audio::ParseAudioOut(v);
            } catch (const audio::AudioError& error) {
              return error.what();
            }
            return "";
          },
          "default|none|DEVICE"));
}

audio::OpenedAudioOut OpenAudioOutOrSilent(const std::string& value, const audio::PlayerOptions& timing) {
  audio::OpenedAudioOut out = audio::OpenAudioOut(audio::ParseAudioOut(value), timing);
  if (!out.note.empty()) std::fprintf(stderr, "note: %s\n", out.note.c_str());
  return out;
}

audio::OpenedAudioOut OpenAudioOutForScene(const std::string& value, const std::filesystem::path& scene) {
  if (scene.empty() || !audio::ParseAudioOut(value).enabled || !SceneHasLines(authoring::LoadScene(scene))) return {};
  return OpenAudioOutOrSilent(value);
}

}  // namespace arview::app
