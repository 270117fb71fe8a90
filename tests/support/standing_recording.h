#pragma once
// A constructed recording of a person standing, for tests only (the product learns only from
// recordings the user gives it): a pelvis on two straight legs whose feet stay exactly where they
// are, resting over the left foot, between the feet or over the right, and shifting its weight
// between those rests, with rest and shift durations known to the test.

#include "anim/balance_shift.h"
#include "anim/character.h"
#include "anim_authoring/balance.h"
#include "anim_authoring/idle_learning.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace arview::testing {

// Hips 1 unit above the floor on two legs (hip, knee, ankle: 0.5 + 0.5), the feet 0.3 apart along
// x. With `torso`: a spine, chest, neck and head above the hips (1.75 tall) and an arm on each side.
inline anim::Skeleton StandingSkeleton(bool torso) {
  anim::Skeleton sk;
  auto add = [&](const std::string& name, int parent, const Eigen::Vector3d& offset) {
    sk.names.push_back(name);
    sk.parents.push_back(parent);
    anim::Transform t;
    t.translation = offset;
    sk.rest.push_back(t);
    sk.inverse_bind.push_back(Eigen::Matrix4d::Identity());
  };
  add("Hips", -1, {0, 1, 0});
  add("LeftUpLeg", 0, {-0.15, 0, 0});
  add("LeftLeg", 1, {0, -0.5, 0});
  add("LeftFoot", 2, {0, -0.5, 0});
  add("RightUpLeg", 0, {0.15, 0, 0});
  add("RightLeg", 4, {0, -0.5, 0});
  add("RightFoot", 5, {0, -0.5, 0});
  if (torso) {
    add("Spine", 0, {0, 0.1, 0});
    add("Chest", 7, {0, 0.3, 0});
    add("Neck", 8, {0, 0.2, 0});
    add("Head", 9, {0, 0.15, 0});
    add("LeftArm", 8, {-0.2, 0.15, 0});
    add("RightArm", 8, {0.2, 0.15, 0});
  }
  return sk;
}

// One rest of a constructed recording: where the weight is, for how long (seconds), the head's
// turn there (radians about up: rests of one category differ by it), and how long the shift to
// the next rest takes (unused after the last).
struct Stay {
  anim::Support support = anim::Support::kBoth;
  double rest = 1;
  double head = 0;
  double shift = 0.6;
};

// The pelvis's lateral position over each support: x = −0.12 over the left foot (support 0.1 of
// the way from the left foot to the right), 0 between, +0.12 over the right (0.9).
inline double PelvisOver(anim::Support s) { return s == anim::Support::kLeft ? -0.12 : s == anim::Support::kRight ? 0.12 : 0.0; }

// The stays one after the other, each shift a cosine ease from one rest to the next. The legs
// turn (about the forward axis) so that the feet stay put under the moving pelvis, which lowers
// as it leaves the middle; the spine leans with the weight and the head turns between rests.
// Keys at 60 Hz on the skeleton of StandingSkeleton(true).
inline anim::Clip StandingRecording(const std::vector<Stay>& stays) {
  double duration = 0;
  for (std::size_t i = 0; i < stays.size(); ++i) duration += stays[i].rest + (i + 1 < stays.size() ? stays[i].shift : 0.0);
  anim::Clip c;
  c.name = "standing";
  c.duration = duration;
  c.tracks.resize(StandingSkeleton(true).size());
  const Eigen::Vector3d forward_axis = Eigen::Vector3d::UnitZ(), up = Eigen::Vector3d::UnitY();
  for (int k = 0; k <= static_cast<int>(std::round(duration * 60)); ++k) {
    const double t = k / 60.0;
    // The stay t falls in, and how far into the shift after its rest (0 while resting).
    std::size_t i = 0;
    double from = 0;
    for (; i + 1 < stays.size() && t >= from + stays[i].rest + stays[i].shift; ++i) from += stays[i].rest + stays[i].shift;
    const double into_shift = i + 1 < stays.size() ? std::clamp((t - from - stays[i].rest) / stays[i].shift, 0.0, 1.0) : 0.0;
    const double ease = 0.5 * (1 - std::cos(M_PI * into_shift));
    const Stay& next = stays[std::min(i + 1, stays.size() - 1)];
    const double x = PelvisOver(stays[i].support) + ease * (PelvisOver(next.support) - PelvisOver(stays[i].support));
    const double head = stays[i].head + ease * (next.head - stays[i].head);
    const double tilt = -std::asin(x);  // hip → foot along (−x, −√(1 − x²)): the feet stay put
    c.tracks[0].translation.push_back({t, {x, std::sqrt(1 - x * x), 0}});
    for (int leg : {1, 4}) c.tracks[leg].rotation.push_back({t, Eigen::Quaterniond(Eigen::AngleAxisd(tilt, forward_axis))});
    for (int foot : {3, 6}) c.tracks[foot].rotation.push_back({t, Eigen::Quaterniond(Eigen::AngleAxisd(-tilt, forward_axis))});
    c.tracks[7].rotation.push_back({t, Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * x, forward_axis))});
    c.tracks[10].rotation.push_back({t, Eigen::Quaterniond(Eigen::AngleAxisd(head, up))});
  }
  return c;
}

// Eleven rests (four left, three both, four right) joined by ten transitions of all six kinds,
// each rest with its own head turn, so that the resting postures of a category differ.
inline std::vector<Stay> LongStanding() {
  using anim::Support;
  constexpr Support kL = Support::kLeft, kB = Support::kBoth, kR = Support::kRight;
  return {{kL, 2.0, 0.00, 0.6}, {kB, 1.2, 0.15, 0.6},  {kR, 2.6, -0.10, 0.8}, {kL, 1.4, 0.20, 0.6},
          {kR, 1.6, -0.15, 0.6}, {kB, 2.2, 0.05, 0.6}, {kL, 3.0, 0.10, 0.8},  {kR, 2.0, -0.20, 0.6},
          {kL, 1.8, 0.12, 0.6}, {kB, 1.6, -0.05, 0.6}, {kR, 2.0, 0.00, 0.6}};
}

// A person (StandingSkeleton(true)) whose one clip is the recording, the idle model learned from
// that clip (whose PCA the balance distance uses) and the balance model learned from it.
struct StandingPerson {
  anim::Character person;
  anim::IdleModel idle;
  std::optional<anim::BalanceModel> balance;
  authoring::BalanceLearningReport report;
  std::shared_ptr<const anim::Skeleton> skeleton() const { return std::make_shared<const anim::Skeleton>(person.skeleton); }
};

inline std::unique_ptr<StandingPerson> LearnFromStanding(const std::vector<Stay>& stays) {
  auto l = std::make_unique<StandingPerson>();
  l->person.source = "constructed";
  l->person.skeleton = StandingSkeleton(true);
  l->person.clips = {StandingRecording(stays)};
  const authoring::IdleSource own{&l->person, {&l->person.clips[0]}, true};
  const authoring::IdleLearningOptions options;
  l->idle = authoring::LearnIdleModel(l->person.skeleton, {own}, options);
  l->balance = authoring::LearnBalanceModel(l->person.skeleton, own, l->idle, options, {}, &l->report);
  return l;
}

}  // namespace arview::testing
