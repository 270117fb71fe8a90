#pragma once
// What a recording holds for balance shifts (thesis §3.3, docs/method.md §3): the thesis learns
// resting-posture categories (weight on the left foot, on the right foot, on both), the
// recorded transitions between them, transition probabilities and dwell times, from a person
// standing. Before any of that can be learned the data must hold such standing: this measures,
// per clip, how much of it does.
//
// Per frame (resampled at `rate`), in the data's model space:
//   - planted: both feet (ankle joints, found by name) move slower than `max_foot_speed`;
//   - support: where the pelvis (the legs' common parent) lies between the feet along the
//     line joining them, 0 over the left foot, 1 over the right; its category is left (below
//     `one_foot`), right (above 1 − `one_foot`) or both;
//   - resting: planted, and the pelvis slower than `max_rest_speed` (horizontal).
// A rest is a run of resting frames of one category lasting `min_rest_seconds` or more; a
// transition is the stretch between two consecutive rests of different categories during which
// both feet stay planted (a step or a jump in between is not a balance shift). Speeds are in
// body heights (the median over the frames of the joints' extent along `up`) per second.
//
//   BalanceAnalysis a = AnalyseBalance(cmu.skeleton, cmu.clips[0], {});
//   a.Summary();   // seconds planted (per support category), resting, rests, transitions
//
// LearnBalanceModel then learns the balance-shift layer (anim/balance_shift.h) from what the
// analysis finds in a recording: the transitions as segments, their ends as the resting
// postures, the counts and dwell times as the category graph. A recording without a transition
// teaches nothing: no model, and the report says what was found instead.

#include "anim/balance_shift.h"
#include "anim/character.h"
#include "anim_authoring/idle_learning.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace arview::authoring {

struct BalanceOptions {
  double rate = 30;
  double max_foot_speed = 0.1;     // body heights per second
  double max_rest_speed = 0.05;    // body heights per second, the pelvis along the floor
  double one_foot = 1.0 / 3;       // support below this (or above 1 − this): weight on one foot
  double min_rest_seconds = 0.5;
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  // Joints by name instead of the ones found (e.g. marker data: LANK, RANK, and the four waist
  // markers, whose mean is the pelvis). Empty: found by name.
  std::string left_foot, right_foot;
  std::vector<std::string> pelvis;
};

struct BalanceAnalysis {
  struct Rest {
    anim::Support support = anim::Support::kBoth;
    double from = 0, to = 0;  // seconds
  };
  struct Transition {
    anim::Support from_support = anim::Support::kBoth, to_support = anim::Support::kBoth;
    double from = 0, to = 0;  // seconds: the end of one rest to the start of the next
    int rest = -1;            // the index of the rest it leaves
  };
  std::string source;              // "file clip"
  double seconds = 0;
  int frames = 0;
  double height = 0;               // body height used for the speeds (data units; median extent along up)
  double planted_seconds = 0;      // both feet planted
  double resting_seconds = 0;      // planted and the pelvis still
  std::array<double, 3> planted_by_support{};  // planted seconds per support category
  double longest_planted_seconds = 0;          // the longest run of planted frames
  double min_rest_seconds = 0;                 // the options' (for the summary)
  std::vector<Rest> rests;
  std::vector<Transition> transitions;

  // Category pairs (from, to) with at least one transition.
  int TransitionPairs() const;
  std::string Summary() const;
};

// Throws Error when the skeleton has no left and right leg with a foot found by name.
BalanceAnalysis AnalyseBalance(const anim::Skeleton& skeleton, const anim::Clip& clip, const BalanceOptions& options,
                               const std::string& source = "");

struct BalanceLearningOptions {
  BalanceOptions analysis;  // up: the data's (+Y for motion capture, the character's for its own clips)
  int components = 10;      // of the idle PCA, in the distance between postures
};

struct BalanceLearningReport {
  std::string source;                      // the recording
  std::vector<BalanceAnalysis> clips;      // what each clip holds
  std::array<int, anim::kSupports> rests{};      // rests found, per category
  int transitions = 0;                     // transitions found
  // Learned (model given): categories that can be left, segments kept, dwell ranges.
  bool learned = false;
  int segments = 0;
  std::array<std::array<int, anim::kSupports>, anim::kSupports> counts{};
  std::array<double, anim::kSupports> dwell_min{}, dwell_max{};
  int components = 0;
  // One line: what was found, and what was learned or why nothing was.
  std::string Summary() const;
};

// The balance-shift model from `source`'s clips (a recording of a person standing: motion
// capture mapped onto the character as the idle learner maps it, or the character's own clips),
// in the posture layout and PCA of `idle` (learned with `idle_options`). Only categories from
// which the recorded graph can always go on are kept (a category whose only transitions lead
// where none was recorded out would end the walk). Returns nothing when no transition remains;
// the report says what the recording held (a recording without a transition is only analysed:
// `idle` is not read then). Throws Error when the source maps onto other joints than the idle
// model, or has no feet found by name.
std::optional<anim::BalanceModel> LearnBalanceModel(const anim::Skeleton& character, const IdleSource& source, const anim::IdleModel& idle,
                                              const IdleLearningOptions& idle_options, const BalanceLearningOptions& options,
                                              BalanceLearningReport* report = nullptr);

}  // namespace arview::authoring
