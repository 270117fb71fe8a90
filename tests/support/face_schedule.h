#pragma once
// A face on a small rig, for the allocation test and bench_anim: a 4-joint chain whose one mesh
// (a grid of 40x40 vertices) has `targets` morph targets, and an animator whose schedule plays
// two clips keying every target's weight at 30 keys/s (one of them mirrored) under a third on a
// layer above that keys half of them, with the joints moving too.

#include "anim/animator.h"
#include "anim/blendable.h"
#include "anim/morph.h"
#include "anim/schedule.h"

#include <cmath>
#include <memory>
#include <random>
#include <string>

namespace arview::testing {

class FaceSchedule {
 public:
  explicit FaceSchedule(int targets, unsigned seed = 7) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    character_.source = "face-schedule";
    for (int j = 0; j < 4; ++j) {
      character_.skeleton.names.push_back(j == 0 ? "Root" : j == 1 ? "LeftEye" : j == 2 ? "RightEye" : "Jaw");
      character_.skeleton.parents.push_back(j == 0 ? -1 : 0);
      anim::Transform t;
      t.translation = Eigen::Vector3d(0, 0.1 * j, 0);
      character_.skeleton.rest.push_back(t);
      character_.skeleton.inverse_bind.push_back(Eigen::Matrix4d::Identity());
    }
    anim::Mesh mesh;
    mesh.name = "face";
    constexpr int kSide = 40;
    for (int y = 0; y < kSide; ++y)
      for (int x = 0; x < kSide; ++x) {
        mesh.positions.emplace_back(x / float(kSide), y / float(kSide), 0.f);
        mesh.normals.push_back(Eigen::Vector3f::UnitZ());
        mesh.joints.push_back({0, 0, 0, 0});
        mesh.weights.emplace_back(1, 0, 0, 0);
      }
    character_.meshes.push_back(mesh);
    for (int k = 0; k < targets; ++k) {
      std::vector<Eigen::Vector3f> deltas(mesh.positions.size(), Eigen::Vector3f::Zero());
      for (int v = k * 7 % 1600; v < 1600; v += 5) deltas[v] = Eigen::Vector3f(0, 0, 0.01f * float(u(rng)));
      anim::AddMorphTarget(character_, "target" + std::to_string(k), 0, deltas);
    }
    skeleton_ = std::make_shared<const anim::Skeleton>(character_.skeleton);
    schedule_ = std::make_shared<anim::Schedule>(skeleton_);
    auto clip = [&](double duration, int every) {
      auto c = std::make_shared<anim::Clip>();
      c->name = "face" + std::to_string(every);
      c->duration = duration;
      c->tracks.resize(skeleton_->size());
      for (int i = 0; i <= static_cast<int>(duration * 30); ++i) {
        const double t = i / 30.0;
        c->tracks[3].rotation.push_back({t, Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * u(rng), Eigen::Vector3d::UnitX()))});
      }
      for (int k = 0; k < targets; k += every) {
        anim::WeightTrack track{k, {}};
        for (int i = 0; i <= static_cast<int>(duration * 30); ++i) track.weights.push_back({i / 30.0, 0.5 + 0.5 * u(rng)});
        c->weight_tracks.push_back(std::move(track));
      }
      return std::make_shared<anim::ClipSource>(skeleton_, c);
    };
    schedule_->Add({std::make_shared<anim::Loop>(clip(2.0, 1)), {}, 0, true, "talk"});
    schedule_->Add({std::make_shared<anim::Mirror>(std::make_shared<anim::Loop>(clip(1.5, 1)), skeleton_), {}, 0, true, "mirrored"});
    schedule_->Add({std::make_shared<anim::Loop>(clip(3.0, 2)), {}, 0, true, "smile", 1});
    schedule_->SetLiveWeight(2, 0.5);
    animator_ = std::make_unique<anim::Animator>(skeleton_, schedule_);
  }

  // The next frame, then a face layer's write of target 0 (as a blink would).
  const anim::AnimatorFrame& Step(double dt) {
    time_ += dt;
    const anim::AnimatorFrame& f = animator_->Update(time_, {});
    if (!f.morph_weights.empty()) animator_->SetMorphWeight(0, static_cast<float>(0.5 + 0.5 * std::sin(time_)));
    return f;
  }

  const anim::Character& character() const { return character_; }

 private:
  anim::Character character_;
  std::shared_ptr<const anim::Skeleton> skeleton_;
  std::shared_ptr<anim::Schedule> schedule_;
  std::unique_ptr<anim::Animator> animator_;
  double time_ = 0;
};

}  // namespace arview::testing
