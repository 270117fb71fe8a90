#include "app/session/ar_session.h"
#include "app/session/scene_lines.h"

#include "anim_authoring/character_builder.h"
#include "app/session/character_setup.h"
#include "app/session/keyframe_appearance.h"
#include "recordings/trajectory.h"
#include "base/stats.h"

#include <cstdio>
#include <algorithm>
#include <exception>
#include <memory>
#include <iostream>
#include <optional>
#include <thread>

#include "app/pipeline/pipeline_report.h"
#include "base/progress.h"
#include "video/sinks.h"
#include "tracker/tracker.h"

namespace arview::app {

double MedianFrameRate(const std::vector<recordings::FrameEntry>& frames) {
  std::vector<double> dt;
  for (size_t i = 1; i < frames.size(); ++i) dt.push_back(frames[i].timestamp - frames[i - 1].timestamp);
  if (dt.empty()) return 30;
  const double median = Median(dt);
  // Still-photo datasets are stamped one second apart; a 1 fps video of them would be a slide show.
  if (median >= 0.5) return 10;
  return median > 0 ? 1.0 / median : 30;
}

namespace {

// "augmenting frames: 120/300 (40%) 118 localized, 2 dropped, resident 300.1 MiB, latency 21 ms"
std::string ProgressDetail(const PipelineReport& r, double rss_mib) {
  char detail[192];
  std::snprintf(detail, sizeof(detail), "%zu localized, %zu dropped, resident %.1f MiB, latency %.0f ms", r.frames_localized,
                r.frames_dropped + static_cast<size_t>(r.source.driver_dropped), rss_mib, r.recent_latency_ms);
  return detail;
}

// The window's title: "arview | 29.8 fps, latency 22 ms, 3 dropped, 118/120 localized"
std::string WindowStatus(const PipelineReport& r) {
  char status[160];
  std::snprintf(status, sizeof(status), "%.1f fps, latency %.0f ms, %zu dropped, %zu/%zu localized", r.recent_fps,
                r.recent_latency_ms, r.frames_dropped + static_cast<size_t>(r.source.driver_dropped), r.frames_localized,
                r.frames_processed);
  return status;
}

// Said before the first frame: frames from a camera other than the map's are tracked with their
// own camera, which the user should know was taken. (Missing keyframe images are not said: the
// fixed floors then used show in the numbers of each lost frame's cause.)
std::optional<std::string> CameraNote(const calib::Camera& map_camera, const calib::Camera& frame_camera) {
  const tracker::LossDiagnoser compare(map_camera, frame_camera, tracker::AppearanceReference{});
  const auto difference = compare.CameraDifference(frame_camera.Size());
  if (!difference) return std::nullopt;
  return "the frames' camera differs from the map's (" + *difference +
         "): they are tracked with their own camera, the scene stays in the map's units";
}

}  // namespace

std::optional<calib::Camera> RecordingTrackingCamera(const calib::Camera& map_camera, const calib::Camera& recording) {
  if (!recording.calibrated) return std::nullopt;
  const tracker::LossDiagnoser compare(map_camera, recording, tracker::AppearanceReference{});
  if (!compare.CameraDifference(recording.Size())) return std::nullopt;
  return recording;
}

bool SceneHasLines(const authoring::Scene& scene) {
  return std::any_of(scene.characters.begin(), scene.characters.end(),
                     [](const authoring::CharacterSpec& c) { return !c.lines.empty(); });
}

void SessionOptions::Check(const OptionNames& names) const {
  RequireOption(sink_fps > 0, names("sink_fps"), "above 0", sink_fps);
  compositor.Check(names.Nested("compositor"));
  fade.Check(names.Nested("fade"));
  pipeline.Check(names.Nested("pipeline"));
  tracker.Check(names.Nested("tracker"));
}

SessionResult RunSession(recordings::FrameSource& source, cv::Size source_size, const map::Map& map,
                         const std::string& map_name, const SessionOptions& o) {
  const Clock::time_point command_start = o.command_start.value_or(Clock::now());
  o.Check();
  // The frames are tracked and drawn over with their own camera; the map gives only the world.
  const calib::Camera& camera = o.frame_camera ? *o.frame_camera : map.camera;
  if (source_size != camera.Size()) {
    throw Error(source.Name() + ": frames are " + std::to_string(source_size.width) + "x" +
                std::to_string(source_size.height) + " but their camera " +
                (o.frame_camera ? std::string("is calibrated") : "(the map " + map_name + "'s) is calibrated") +
                " for " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  // The eyes' disparity is --ipd in map units: metres only on a metric map.
  if (o.compositor.hmd && o.compositor.stereo_character && !map.frame.metric()) {
    std::fprintf(stderr, "warning: %s has no scale, so --ipd %.3g is in its arbitrary units and the character's depth "
                         "is wrong ('arview map scale' makes the map metric)\n",
                 map_name.c_str(), o.compositor.ipd_m);
  }
  // The scene (its lines and a dialogue decide whether a video gets an audio track), then the output: a window
  // without a display, or an unwritable file, is said before anything else loads.
  const bool first_view = o.scene_file.empty() && o.first_view;
  std::optional<authoring::Scene> scene;
  if (!o.scene_file.empty()) scene = authoring::LoadScene(o.scene_file);
  if (first_view) scene = o.first_view->scene;
  std::unique_ptr<video::FrameSink> sink =
      video::OpenSink(o.sink, ArCompositor::OutputSizeFor(camera, o.compositor), o.sink_fps, o.window,
                      o.audio_track && scene && (SceneHasLines(*scene) || o.dialogue.enabled())
                          ? std::optional(video::AudioTrackOptions{})
                          : std::nullopt);
  SessionSound sound(o.sound_out, *sink, o.sink_fps);
  // --stats: each frame's record goes to disk as it comes (pipeline_report.h), none is kept.
  std::optional<StatsFileWriter> stats;
  PipelineOptions pipeline = o.pipeline;
  if (!o.stats_out.empty()) {
    stats.emplace(o.stats_out);
    pipeline.on_frame_log = [&stats](const FrameLog& frame) { stats->Add(frame); };
  }
  // --trajectory: each localized frame's pose goes to disk as it comes (recordings/trajectory.h).
  std::optional<recordings::TumFileWriter> trajectory;
  if (!o.trajectory_out.empty()) {
    trajectory.emplace(o.trajectory_out, "arview: raw refined poses of localized frames");
    pipeline.on_localized_pose = [&trajectory](const recordings::StampedPose& pose) { trajectory->Add(pose); };
  }
  if (sound.active()) {
    pipeline.on_frame_log = [stats_log = std::move(pipeline.on_frame_log), &sound](const FrameLog& frame) {
      const Clock::time_point shown = Clock::now();  // the sink has just written (shown) the frame
      if (stats_log) stats_log(frame);
      sound.OnFrameShown(frame, shown);
    };
  }
  Clock::time_point step = Clock::now();
  const auto seconds_of_step = [&step] {
    const Clock::time_point now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - step).count();
    step = now;
    return seconds;
  };
  // The GL context first: creating it sets LP_NUM_THREADS, which must not race with another
  // thread's getenv. Then the tracker starts (its descriptor index, its warm-up: about 1 s) on a
  // thread of its own while this one loads the characters and warms the renderer up (its shaders
  // and llvmpipe's first draw: 1-3 s on a loaded machine), so that the first frame pays neither.
  std::unique_ptr<render::OffscreenContext> context = render::OffscreenContext::Create(o.compositor.gl);
  const double context_seconds = seconds_of_step();
  std::optional<tracker::Tracker> tracker;
  std::optional<tracker::LossDiagnoser> diagnoser;
  std::exception_ptr tracker_error;
  double tracker_seconds = 0;
  // Joined below, or by its destructor however this thread leaves (a bad scene, a renderer that
  // fails).
  std::jthread tracker_start([&] {
    try {
      const Clock::time_point t0 = Clock::now();
      tracker.emplace(map, camera, o.tracker);
      // The tracker projects with the frames' camera, so the cause of a lost frame is never that
      // camera's difference from the map's.
      diagnoser.emplace(camera, camera, KeyframeAppearance(map, MapFolder(map_name), o.recording));
      tracker->WarmUp();  // before the first frame, so that its latency is a relocalization's only
      tracker_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    } catch (...) {
      tracker_error = std::current_exception();
    }
  });

  std::vector<std::unique_ptr<authoring::AnimatedCharacter>> characters;
  std::vector<std::unique_ptr<LayeredAnimator>> animators;
  std::vector<LayeredAnimator*> animator_ptrs;
  std::vector<const anim::PlacedCharacter*> character_ptrs;
  const std::function<void(const speech::Utterance&)> on_utterance = [&o, &sound](const speech::Utterance& u) {
    sound.OnUtterance(u);
    if (o.on_utterance) o.on_utterance(u);
  };
  if (scene) {
    for (const authoring::CharacterSpec& spec : scene->characters) {
      characters.push_back(std::make_unique<authoring::AnimatedCharacter>(spec));
      animators.push_back(MakeLayeredAnimator(*characters.back(), "", o.fade));
      // The lines are synthesized here, at load, on the speech queue's thread: the frames only say them.
      if (std::unique_ptr<CharacterSpeech> speech = MakeCharacterSpeech(*characters.back(), on_utterance,
                                                                            o.sound_out ? kLiveSpeechDelay : 0.0))
        animators.back()->SetSpeech(std::move(speech));
      for (const std::string& note : animators.back()->notes()) std::cerr << "note: " << note << "\n";
      animator_ptrs.push_back(animators.back().get());
      character_ptrs.push_back(characters.back().get());
    }
  }

  // The dialogue after the characters: it answers through the first one's speech.
  std::unique_ptr<SessionDialogue> dialogue;
  if (o.dialogue.enabled()) {
    if (characters.empty())
      throw Error(o.dialogue.dialogue_file.string() + ": a dialogue needs a character to answer (not with --no-figure)");
    // The replies go where the scene's lines go (the sound, the video's track, o.on_utterance).
    dialogue = std::make_unique<SessionDialogue>(o.dialogue, *characters.front(), *animators.front(), on_utterance,
                                                 [](const std::string& line) { std::cerr << "note: " << line << "\n"; });
    sound.AddHeardAudio(dialogue->heard_samples());
    for (const std::string& note : dialogue->load_notes()) std::cerr << "note: " << note << "\n";
  }

  const double characters_seconds = seconds_of_step();
  ArCompositor compositor(camera, character_ptrs, o.compositor, std::move(context));
  const double renderer_seconds = context_seconds + seconds_of_step();
  if (!o.quiet) std::cerr << "renderer: " << compositor.Description() << "\n";
  for (const std::string& note : compositor.LoadNotes()) std::cerr << "note: " << note << "\n";
  const double warmup_seconds = compositor.WarmUp();
  tracker_start.join();
  if (tracker_error) std::rethrow_exception(tracker_error);
  seconds_of_step();
  if (!o.quiet && !tracker->index_note().empty()) std::cerr << "note: " << tracker->index_note() << "\n";
  if (const auto note = CameraNote(map.camera, camera); note && !o.quiet) std::cerr << "note: " << *note << "\n";
  pipeline.diagnoser = &*diagnoser;
  if (first_view && !characters.empty()) {
    // Once, on the render thread (which alone animates and draws the characters), before the
    // first localized frame is animated: its cost is that frame's `animate` time.
    pipeline.on_first_localized = [&o, &characters, &compositor](const tracker::FrameResult& frame) {
      const Clock::time_point start = Clock::now();
      anim::Placement placement = characters.front()->placement();
      placement.anchor = o.first_view->stand_in_front_of(frame.pose);
      characters.front()->SetPlacement(placement);
      compositor.MoveCharacter(0, placement);
      const double milliseconds = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      if (o.first_view->on_placed) o.first_view->on_placed(placement.anchor, frame.pose, milliseconds);
    };
  }
  sink->SetKeyHandler([&compositor, &dialogue](const std::string& key) {
    if (key == "h") compositor.ToggleHud();
    if (key == kPushToTalkKey && dialogue) dialogue->TogglePushToTalk();
  });

  if (dialogue) dialogue->Start();
  Progress progress("augmenting frames");
  double rss_mib = -1;
  std::size_t rss_read_at = 0;
  Clock::time_point status_at{};
  PipelineReport report = RunPipeline(
      source, *tracker, animator_ptrs, compositor, *sink, pipeline,
      [&](const PipelineReport& r) {
        // On the sink's thread, which owns the window: its title twice a second.
        if (const Clock::time_point now = Clock::now(); now - status_at > std::chrono::milliseconds(500)) {
          sink->SetStatus(WindowStatus(r));
          status_at = now;
        }
        if (o.quiet || o.cancel.IsCancelled()) return;  // after a Ctrl-C: only the one line
        // Resident memory, read every 100 frames (a soak test follows it on these lines).
        if (r.frames_processed >= rss_read_at + 100 || rss_mib < 0) {
          rss_mib = ResidentMemoryMiB();
          rss_read_at = r.frames_processed;
        }
        progress.Update(static_cast<long>(r.frames_processed), o.expected_frames > 0 ? o.expected_frames
                                                                                      : static_cast<long>(r.frames_processed),
                        ProgressDetail(r, rss_mib));
      },
      [&o] { return o.cancel.IsCancelled(); });
  progress.Finish();
  if (dialogue) {
    dialogue->Stop();
    const CharacterDialogue& answered = *animators.front()->dialogue();
    report.dialogue_turns = answered.turns();
    for (const std::string& problem : answered.problems()) std::cerr << "note: " << problem << "\n";
  }
  if (o.cancel.IsCancelled() && !o.cancel_ends_normally) {
    std::string unwritten = o.output_name.empty() ? std::string() : o.output_name;
    for (const auto& file : {o.trajectory_out, o.stats_out}) {
      if (!file.empty()) unwritten += (unwritten.empty() ? "" : ", ") + file.string();
    }
    o.cancel.ThrowIfCancelled("stopped after " + std::to_string(report.frames_processed) + " frames; " +
                              (unwritten.empty() ? std::string("nothing to keep") : "not written: " + unwritten));
  }

  SessionResult result{std::move(report), compositor.Description(), compositor.Renderer(), sink->Describe()};
  result.tracker_seconds = tracker_seconds;
  result.characters_seconds = characters_seconds;
  result.renderer_seconds = renderer_seconds;
  result.warmup_seconds = warmup_seconds;
  for (const std::unique_ptr<LayeredAnimator>& a : animators)
    if (a->speech()) result.utterances.insert(result.utterances.end(), a->speech()->utterances().begin(), a->speech()->utterances().end());
  std::stable_sort(result.utterances.begin(), result.utterances.end(),
                   [](const speech::Utterance& a, const speech::Utterance& b) { return a.start_s < b.start_s; });
  if (result.report.first_output) {
    result.seconds_to_first_output = std::chrono::duration<double>(*result.report.first_output - command_start).count();
    if (result.report.first_localized_output) {
      result.seconds_to_first_localized_output =
          std::chrono::duration<double>(*result.report.first_localized_output - command_start).count();
    }
  }
  if (trajectory) trajectory->Finish();
  result.sound = sound.Finish();
  if (stats) {
    stats->Finish(result.report, result.renderer, result.renderer_info,
                  sound.active() ? nlohmann::ordered_json{{"sound", SoundJson(result.sound)}} : nlohmann::ordered_json());
  }
  result.loss_advice = LossAdviceText(result.report, map_name);
  return result;
}

}  // namespace arview::app
