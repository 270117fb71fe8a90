#pragma once
// Learning the idle model (anim/idle.h) from real motion (thesis chapter 3):
//   1. Motion capture mapped onto the character by a humanoid joint-name map (spine, neck/head,
//      arm and leg chains found by name in CMU, Mixamo, BCN_Epileptic, CesiumMan and common
//      glTF rigs; overridable), retargeted as model-space rotation changes about the data's
//      mean posture applied to the character's rest pose — so the character keeps its own
//      stance and takes the data's variations; or the character's own clips, as they are.
//   2. Motion capture: standing segments only — frames whose root moves slower than 0.1 body
//      heights per second and whose mapped joints turn slower than 2 rad/s, in runs of at least
//      1 s (the CMU captures on every machine hold none: see docs/anim.md). The character's own
//      clips are taken whole (the scene names them as idle material).
//   3. PCA over the postures (exp-map rotations relative to rest + root offset).
//   4. Per component: extrema of the (lightly smoothed) signal, k-means on (interval, value),
//      transition counts between consecutive extrema's clusters.
// What the data holds is reported (frames, seconds and segments used, variance explained);
// nothing is invented: no segment, no model.

#include "anim/character.h"
#include "anim/idle.h"

#include <map>
#include <string>
#include <vector>

namespace arview::authoring {

// Character joint → data joint pairs found by the humanoid chains (and `overrides`: data joint
// name → character joint name, which replace what the chains found for that character joint).
std::vector<std::pair<int, int>> HumanoidJointPairs(const anim::Skeleton& character, const anim::Skeleton& data,
                                                    const std::map<std::string, std::string>& overrides = {});

struct IdleSource {
  const anim::Character* data = nullptr;       // motion capture, or the character itself
  std::vector<const anim::Clip*> clips;        // its clips to learn from
  bool is_character = false;             // the character's own clips: no retargeting
};

struct IdleLearningOptions {
  int components = 10;
  int clusters = 6;                      // k-means clusters per component (fewer if few extrema)
  double min_segment_seconds = 1.0;
  double max_root_speed = 0.1;           // body heights per second
  double max_joint_speed = 2.0;          // rad/s
  std::map<std::string, std::string> joint_map;
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ(), up = Eigen::Vector3d::UnitY();  // the character's
};

struct IdleLearningReport {
  int frames = 0;              // standing frames used
  double seconds = 0;
  int segments = 0;
  double source_seconds = 0;   // all frames looked at
  int mapped_joints = 0;
  double variance_explained = 0;  // by the kept components
  std::vector<int> extrema;    // per component
  std::vector<int> clusters;   // per component
  std::string Summary() const;
};

// Throws Error (naming the source) when nothing maps, or no standing segment is found.
anim::IdleModel LearnIdleModel(const anim::Skeleton& character, const std::vector<IdleSource>& sources, const IdleLearningOptions& options,
                         IdleLearningReport* report = nullptr);

// The training postures (standing frames, per segment) as the learner sees them, for checks:
// the same retargeting and segment selection as LearnIdleModel. Each sequence is sampled at
// `rate` Hz.
struct PostureSequences {
  struct Stillest {
    double root = 1e300, joint = 1e300, score = 1e300;  // speeds in the stillest window
    std::string where;                                   // "file at t s"
  };
  std::vector<std::vector<Eigen::VectorXd>> segments;
  Stillest stillest;
  std::vector<int> joints;
  int root = 0;
  double rate = 0;
};
PostureSequences TrainingPostures(const anim::Skeleton& character, const std::vector<IdleSource>& sources,
                                  const IdleLearningOptions& options, double rate = 30.0);

// Every frame of `clip` (a clip of source.data) at `rate` Hz as a posture in the layout the
// learner gives `source` (retargeted about the clip's mean posture, or the character's own
// rotations), with the character joints of that layout in `joints`: what the balance-shift
// learner (balance.h) reads a recording as.
std::vector<Eigen::VectorXd> ClipPostures(const anim::Skeleton& character, const IdleSource& source, const anim::Clip& clip,
                                          const IdleLearningOptions& options, double rate,
                                          std::vector<int>* joints = nullptr);

}  // namespace arview::authoring
