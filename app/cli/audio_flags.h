#pragma once
// `--audio-out default|none|<device>` for the commands that play the character's lines (run,
// replay, demo: issue 53's wiring adds it to them). The flag's value is checked as CLI11 parses
// it (a usage error, exit 2); opening the device is not an error when there is none: one note on
// stderr and the session goes on silent (audio/audio_out.h).

#include <CLI/CLI.hpp>

#include <filesystem>
#include <string>

#include "audio/audio_out.h"

namespace arview::app {

// Adds --audio-out to `cmd`, bound to `value` (its default: what `value` holds, "default").
void AddAudioOutFlag(CLI::App* cmd, std::string& value);

// The player `value` asks for (none for "none"), or none and the note "note: no sound: ..." on
// stderr when the device cannot be opened.
audio::OpenedAudioOut OpenAudioOutOrSilent(const std::string& value, const audio::PlayerOptions& timing = {});

// The player for a session on `scene` (SessionOptions::sound_out): as OpenAudioOutOrSilent when
// the scene's characters have lines; none, and nothing said, when there is no scene or nothing in
// it is said (a device is not opened for nothing).
audio::OpenedAudioOut OpenAudioOutForScene(const std::string& value, const std::filesystem::path& scene);

}  // namespace arview::app
