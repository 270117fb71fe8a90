// A scene character's lines (issue 53): the visemes on the figure's face and jaw, the lips closing
// on the mesh at every p, b and m, the markup's actions in the schedule, the cues, the errors.

#include "app/session/scene_lines.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "anim/morph.h"
#include "app/session/character_setup.h"
#include "figure/humanoid.h"

namespace arview::app {
namespace {

constexpr double kFrame = 1.0 / 30;  // one video frame

std::string Quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// The figure at the map's origin (facing +Z) with one line per cue.
authoring::CharacterSpec FigureSpec(const std::vector<std::pair<std::string, std::string>>& lines, const std::string& voice = "slt",
                                    const std::string& extra = "") {
  figure::RegisterBuiltinCharacters();
  std::string yaml = "characters:\n  - asset: builtin:figure\n    lookat: {base_clip: Idle}\n"
                     "    keys: [{azimuth: 0, generate: lookat}, {azimuth: 90, generate: lookat}, {azimuth: 180, generate: lookat},"
                     " {azimuth: 270, generate: lookat}]\n    gaze: {seed: 3}\n    voice: " + voice + "\n" + extra;
  if (!lines.empty()) yaml += "    lines:\n";
  for (const auto& [when, say] : lines) yaml += "      - when: " + when + "\n        say: " + Quoted(say) + "\n";
  return authoring::ParseScene(yaml, "lines.yaml").characters.at(0);
}

struct Speaker {
  explicit Speaker(const authoring::CharacterSpec& spec, double start_delay_s = 0) : character(spec) {
    animator = MakeLayeredAnimator(character);
    auto speech = MakeCharacterSpeech(character, [this](const speech::Utterance& u) { started.push_back(u); }, start_delay_s);
    if (speech) animator->SetSpeech(std::move(speech));
  }
  authoring::AnimatedCharacter character;
  std::unique_ptr<LayeredAnimator> animator;
  std::vector<speech::Utterance> started;
};

const Eigen::Vector3d kInFront(0.2, 1.6, 1.0);  // the viewer's eyes, 1 m in front of the figure

// The lips' vertical clearance at the mouth's middle on the skinned and morphed mesh (the upper
// lip's lowest vertex minus the lower lip's highest, within 2 mm of the middle, in the head's
// frame; negative where they overlap).
double LipGapOnTheMesh(const anim::Character& c, const anim::AnimatorFrame& f) {
  const int jaw = c.skeleton.Find("Jaw"), head = c.skeleton.Find("Head");
  const Eigen::Matrix4d to_head = f.model[head].inverse();
  for (const anim::Mesh& mesh : c.meshes) {
    if (mesh.name != "face_lips") continue;
    std::vector<Eigen::Vector3f> p, n;
    anim::ApplyMorphTargets(mesh, f.morph_weights, p, n);
    double upper = 1e9, lower = -1e9;
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      if (std::abs(mesh.positions[v].x()) > 0.002f) continue;
      Eigen::Vector4d skinned = Eigen::Vector4d::Zero();
      for (int k = 0; k < 4; ++k)
        skinned += mesh.weights[v][k] * (f.skinning_matrices[mesh.joints[v][k]].cast<double>() * p[v].cast<double>().homogeneous());
      const double y = (to_head * Eigen::Vector4d(skinned.x(), skinned.y(), skinned.z(), 1)).y();
      if (mesh.joints[v][0] == jaw) lower = std::max(lower, y);
      else upper = std::min(upper, y);
    }
    return upper - lower;
  }
  ADD_FAILURE() << "no face_lips mesh";
  return 0;
}

// Every p, b and m of a set of sentences: the PP target's weight on the frame peaks within one
// video frame of the phone's centre, and the lips are closed there, measured on the mesh.
TEST(SceneLines, TheLipsCloseOnTheMeshAtEveryBilabial) {
  const char* sentences[] = {"Peter picked a basket of purple plums.", "My mom bought a big brown bag.",
                             "Bob, maybe the number is seven.", "Please bring me the map, Pam."};
  const anim::Character* figure = nullptr;
  int bilabials = 0;
  double worst_peak_ms = 0, worst_gap_mm = -1e9;
  for (const char* voice : {"slt", "rms"})
    for (const char* sentence : sentences) {
      Speaker s(FigureSpec({{"start", sentence}}, voice));
      figure = &s.character.character();
      const int pp = figure->skeleton.FindMorphTarget("viseme_PP");
      const ReadyLine& line = s.animator->speech()->lines().at(0);
      const double step = 0.001, end = line.duration_s();
      std::vector<double> pp_weight;
      std::vector<double> centres;
      for (const speech::Phone& ph : line.spoken->phones)
        if (ph.name == "p" || ph.name == "b" || ph.name == "m") centres.push_back((ph.start_s + ph.end_s) / 2);
      ASSERT_FALSE(centres.empty()) << sentence;
      std::size_t next = 0;
      std::vector<double> gaps;
      for (int i = 0; i * step <= end; ++i) {
        const anim::AnimatorFrame& f = s.animator->Update(kInFront, i * step);
        ASSERT_EQ(s.started.size(), 1u);
        pp_weight.push_back(f.morph_weights[pp]);
        if (next < centres.size() && i * step >= centres[next] - step / 2) {
          gaps.push_back(LipGapOnTheMesh(*figure, f));
          ++next;
        }
      }
      ASSERT_EQ(gaps.size(), centres.size());
      for (std::size_t k = 0; k < centres.size(); ++k) {
        // Climb from the centre to the nearest local maximum of PP's weight.
        int i = static_cast<int>(std::lround(centres[k] / step));
        for (;;) {
          if (i + 1 < static_cast<int>(pp_weight.size()) && pp_weight[i + 1] > pp_weight[i]) ++i;
          else if (i > 0 && pp_weight[i - 1] > pp_weight[i]) --i;
          else break;
        }
        const double peak_off = std::abs(i * step - centres[k]);
        worst_peak_ms = std::max(worst_peak_ms, peak_off * 1e3);
        worst_gap_mm = std::max(worst_gap_mm, gaps[k] * 1e3);
        EXPECT_LE(peak_off, kFrame) << voice << " \"" << sentence << "\" bilabial " << k << " at " << centres[k] << " s";
        EXPECT_LT(gaps[k], 0.001) << voice << " \"" << sentence << "\" bilabial " << k << " at " << centres[k] << " s";
        ++bilabials;
      }
    }
  std::printf("[lips] %d bilabials: PP peaks at most %.1f ms from the phone's centre; the widest gap there %.2f mm\n", bilabials,
              worst_peak_ms, worst_gap_mm);
}

// The mouth opens on open vowels through the Jaw joint, not twice (the visemes' jawOpen share is
// taken out), and speech owns the mouth while the expression keeps the brows.
TEST(SceneLines, VisemesOpenTheJawAndSpeechOwnsTheMouthWhileTheExpressionKeepsTheBrows) {
  Speaker s(FigureSpec({{"start", "<face expr=\"surprised\"/>Ah, a large apple and a hot pot!"}}));
  const anim::Skeleton& sk = s.character.character().skeleton;
  const int jaw = sk.Find("Jaw"), jaw_open = sk.FindMorphTarget("jawOpen"), brow = sk.FindMorphTarget("browInnerUp");
  const ReadyLine& line = s.animator->speech()->lines().at(0);
  double widest = 0, jaw_turn_deg = 0, brow_talking = 0;
  bool talking_mode = false;
  for (double t = 0; t <= line.duration_s() + 0.8; t += kFrame) {
    const anim::AnimatorFrame& f = s.animator->Update(kInFront, t);
    if (f.face.talking < 1) continue;
    talking_mode = talking_mode || f.gaze.talking_mode;
    widest = std::max(widest, static_cast<double>(f.face.jaw_open));
    const Eigen::Quaterniond q = f.local[0].rigid[jaw].Rotation() * sk.rest[jaw].rotation.conjugate();
    jaw_turn_deg = std::max(jaw_turn_deg, 2 * std::acos(std::min(1.0, std::abs(q.w()))) * 180 / M_PI);
    // jawOpen: only the visemes' share taken out, and the expression's 0.6 blocked while talking.
    EXPECT_LE(f.morph_weights[jaw_open], 1e-5) << t;
    brow_talking = std::max(brow_talking, static_cast<double>(f.morph_weights[brow]));
  }
  EXPECT_GT(widest, 0.5) << "the open vowels open the mouth";
  EXPECT_NEAR(jaw_turn_deg, widest * 14, 0.5) << "the Jaw joint turns by the opening";
  EXPECT_GT(brow_talking, 0.9) << "the expression keeps the brows while speech has the mouth";
  EXPECT_TRUE(talking_mode) << "talking switches gaze to its talking statistics";
  const anim::AnimatorFrame& after = s.animator->Update(kInFront, line.duration_s() + 0.5);
  EXPECT_EQ(after.face.talking, 0);
  EXPECT_FALSE(after.gaze.talking_mode);
  EXPECT_GT(after.morph_weights[jaw_open], 0.3) << "silent, the expression has the mouth again (surprised: jawOpen 0.6)";
}

// The markup's actions go into the schedule at their word's time; the utterance says when the sound starts.
TEST(SceneLines, TheGestureStartsOnItsWordAndTheUtteranceOnTheFrameClock) {
  Speaker s(FigureSpec({{"start", "Oh, <gesture name=\"Wave\"/>hello there! <gaze at=\"viewer\"/>Nice to see you."}}));
  const ReadyLine& line = s.animator->speech()->lines().at(0);
  ASSERT_EQ(line.actions.size(), 1u);
  std::optional<double> hello;
  for (const speech::SpokenToken& t : line.spoken->tokens)
    if (t.name == "hello") hello = t.start_s;
  ASSERT_TRUE(hello);
  EXPECT_NEAR(line.actions[0].start, *hello, 1e-9);
  ASSERT_EQ(line.gaze_at_viewer.size(), 1u);
  s.animator->Update(std::nullopt, 0.0);  // not tracked yet: nothing said
  EXPECT_TRUE(s.started.empty());
  s.animator->Update(kInFront, 0.4);
  ASSERT_EQ(s.started.size(), 1u);
  EXPECT_DOUBLE_EQ(s.started[0].start_s, 0.4);
  EXPECT_EQ(s.started[0].line->samples.size(), line.spoken->samples.size());
  EXPECT_EQ(s.started[0].origin, "lines.yaml:9");
  const anim::Schedule& schedule = s.animator->animator().schedule();
  const int wave = schedule.FindByName("say:gesture:Wave");
  ASSERT_GE(wave, 0);
  EXPECT_NEAR(schedule.Find(wave)->start, 0.4 + *hello, 1e-9);
  EXPECT_EQ(s.animator->saying(), "Oh, hello there! Nice to see you.");
}

// A gesture on a word takes the upper-body joints its clip moves and leaves the rest to the
// layers below: the wave's arm, not the head the look-at keeps on the viewer (with the whole
// torso masked in, the demo's head turned up to 43 deg off the camera while it said hello); a
// nod's neck and head.
TEST(SceneLines, AGestureMovesTheJointsOfItsClipAndLeavesTheHeadToTheLookAt) {
  Speaker s(FigureSpec({{"start", "<gesture name=\"Wave\"/>Hello. <gesture name=\"Nod\"/>Yes."}}));
  const anim::Skeleton& skeleton = s.character.character().skeleton;
  const std::vector<anim::Action>& actions = s.animator->speech()->lines().at(0).actions;
  ASSERT_EQ(actions.size(), 2u);
  auto weight = [&](const anim::Action& a, const char* joint) {
    return a.params.masks.at(0).rotation.at(static_cast<std::size_t>(skeleton.Find(joint)));
  };
  const anim::Action& wave = actions[0];
  const anim::Action& nod = actions[1];
  EXPECT_EQ(weight(wave, "RightArm"), 1.0);
  EXPECT_EQ(weight(wave, "RightForeArm"), 1.0);
  EXPECT_EQ(weight(wave, "Head"), 0.0);
  EXPECT_EQ(weight(wave, "Neck"), 0.0);
  EXPECT_EQ(weight(wave, "LeftUpLeg"), 0.0);
  EXPECT_EQ(weight(nod, "Head"), 1.0);
  EXPECT_EQ(weight(nod, "Neck"), 1.0);
  EXPECT_EQ(weight(nod, "RightArm"), 0.0);
}

// A live session's delay (app/session/session_sound.h): the cue's frame hands the utterance over
// at once, its start a whole number of frame intervals later; the mouth and the gesture wait for it.
TEST(SceneLines, ADelayedLineStartsOnAWholeFrameAfterItsCueAndTheMouthWaitsForIt) {
  Speaker s(FigureSpec({{"start", "<gesture name=\"Wave\"/>Oh, hello there!"}}), 0.2);
  const double frame = 1.0 / 25;  // 0.2 s is five frames
  double t = 1.0;
  s.animator->Update(std::nullopt, t);  // the frame interval is known from here on
  t += frame;
  s.animator->Update(kInFront, t);
  ASSERT_EQ(s.started.size(), 1u) << "handed over on the cue's frame";
  const double start = s.started[0].start_s;
  EXPECT_NEAR(start, t + 5 * frame, 1e-9);
  const anim::Schedule& schedule = s.animator->animator().schedule();
  const int wave = schedule.FindByName("say:gesture:Wave");
  ASSERT_GE(wave, 0);
  EXPECT_GE(schedule.Find(wave)->start, start);
  for (int i = 1; i < 5; ++i) {
    EXPECT_EQ(s.animator->Update(kInFront, t + i * frame).face.talking, 0.0f) << "frame " << i << " before the start";
  }
  float talking = 0;
  for (int i = 5; i < 12; ++i) talking = std::max(talking, s.animator->Update(kInFront, t + i * frame).face.talking);
  EXPECT_GT(talking, 0.5f) << "the mouth moves from the line's start on";
  // With 0.25 s and frames of 0.1 s the line starts three frames (0.3 s) after its cue.
  Speaker late(FigureSpec({{"start", "Hello."}}), 0.25);
  late.animator->Update(std::nullopt, 0.0);
  late.animator->Update(kInFront, 0.1);
  ASSERT_EQ(late.started.size(), 1u);
  EXPECT_NEAR(late.started[0].start_s, 0.4, 1e-9);
}

// The cues: near (with hysteresis), lost after half a second, found; one line at a time.
TEST(SceneLines, CuesStartTheirLines) {
  Speaker s(FigureSpec({{"near", "You came close."}, {"lost", "Where did you go?"}, {"found", "There you are."}}));
  double t = 0;
  auto run = [&](std::optional<Eigen::Vector3d> at, double seconds) {
    for (double end = t + seconds; t < end; t += kFrame) s.animator->Update(at, t);
  };
  run(Eigen::Vector3d(0, 1.6, 3), 1);
  EXPECT_TRUE(s.started.empty());
  run(Eigen::Vector3d(0, 1.6, 1), 3);
  ASSERT_EQ(s.started.size(), 1u);
  EXPECT_EQ(s.started.back().origin, "lines.yaml:9");
  run(std::nullopt, 0.3);
  EXPECT_EQ(s.started.size(), 1u) << "a short loss says nothing";
  run(Eigen::Vector3d(0, 1.6, 1), 0.5);
  run(std::nullopt, 3);
  ASSERT_EQ(s.started.size(), 2u);
  EXPECT_EQ(s.started.back().origin, "lines.yaml:11");
  run(Eigen::Vector3d(0, 1.6, 1), 3);
  ASSERT_EQ(s.started.size(), 3u);
  EXPECT_EQ(s.started.back().origin, "lines.yaml:13");
  EXPECT_EQ(s.started.size(), 3u) << "near is not re-armed while the viewer stays close";
}

// Behind: the viewer more than 120° from the character's front, once until they come back
// within 90°; a line already being said lets a cue go.
TEST(SceneLines, WalkingBehindTheCharacterSaysItsLine) {
  Speaker s(FigureSpec({{"behind", "Where are you going?"}}));
  double t = 0;
  auto run = [&](const Eigen::Vector3d& at, double seconds) {
    for (double end = t + seconds; t < end; t += kFrame) s.animator->Update(at, t);
  };
  run(Eigen::Vector3d(2, 1.6, 0.5), 1);  // to the side (76° from the front)
  EXPECT_TRUE(s.started.empty());
  run(Eigen::Vector3d(0.5, 1.6, -2), 3);  // behind (166°)
  ASSERT_EQ(s.started.size(), 1u);
  EXPECT_EQ(s.started.back().origin, "lines.yaml:9");
  run(Eigen::Vector3d(2, 1.6, -0.3), 3);  // 99°: not re-armed
  run(Eigen::Vector3d(0.5, 1.6, -2), 3);
  EXPECT_EQ(s.started.size(), 1u);
  run(Eigen::Vector3d(0, 1.6, 2), 1);  // in front: re-armed
  run(Eigen::Vector3d(0.5, 1.6, -2), 3);
  EXPECT_EQ(s.started.size(), 2u);
}

TEST(SceneLines, TheSameLineTwiceGivesTheSameBytesAndCurves) {
  const authoring::CharacterSpec spec = FigureSpec({{"start", "<face expr=\"happy\"/>Hello! Bring me the map, please."}});
  authoring::AnimatedCharacter figure(spec);
  const std::vector<ReadyLine> a = PrepareLines(figure, SceneLineRequests(spec), "awb", "here");
  const std::vector<ReadyLine> b = PrepareLines(figure, SceneLineRequests(spec), "awb", "here");
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].spoken->samples, b[0].spoken->samples);
  speech::VisemeWeights wa, wb;
  for (double t = 0; t < a[0].duration_s(); t += 0.005) {
    a[0].visemes->Sample(t, wa);
    b[0].visemes->Sample(t, wb);
    ASSERT_EQ(wa, wb) << t;
  }
}

std::string ErrorOf(const authoring::CharacterSpec& spec) {
  try {
    Speaker s(spec);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SceneLines, BadLinesAreOneLineNamingTheSceneAndLine) {
  EXPECT_EQ(ErrorOf(FigureSpec({{"start", "Hi <gesture name=\"Dance\"/>there"}})),
            "lines.yaml:9: <gesture> at character 4: the character 'figure' has no gesture 'Dance' (its clips: Idle, WeightShift, "
            "Wave, Point, Nod)");
  EXPECT_EQ(ErrorOf(FigureSpec({{"start", "<face expr=\"bored\"/>Hi"}})),
            "lines.yaml:9: <face> at character 1: the expression 'bored' is not one of happy, sad, angry, surprised, afraid, disgusted");
  EXPECT_EQ(ErrorOf(FigureSpec({{"start", "<gaze at=\"door\"/>Hi"}})),
            "lines.yaml:9: <gaze> at character 1: the character can look at 'viewer' only, not 'door'");
  EXPECT_EQ(ErrorOf(FigureSpec({{"start", "Hi"}}, "kal")), "lines.yaml:6: speech: voice 'kal' is not one of slt, rms or awb");
  EXPECT_EQ(ErrorOf(FigureSpec({{"start", std::string(501, 'a')}})),
            "lines.yaml:9: the text to speak is over the limit of 500 bytes at character 501");
  EXPECT_EQ(ErrorOf(FigureSpec({{"start", "Hi <wave/>"}})),
            "lines.yaml:9: the unknown tag <wave> (the tags are gesture, face or gaze) at character 4");
}

}  // namespace
}  // namespace arview::app
