#pragma once
// The scene file's reader, internal to anim_authoring/ (scene.h's ParseScene and LoadScene are
// its interface): one class whose member functions each read one part of the YAML, split over
// scene_reader.cpp (the scene, its characters, their lines, gaze, anchor, gestures and keys) and
// scene_schedule_reader.cpp (the idle, balance shifts, scopes, masks, curves, objects, actions
// and schedule). The field readers below name the file and line of what they refuse.

#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "anim/view_sphere.h"
#include "anim_authoring/scene.h"
#include "anim_authoring/yaml.h"

namespace arview::authoring {

class SceneReader {
 public:
  using Node = yaml::Node;

  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  Scene Read(const Node& root, const std::filesystem::path& file) const;

  // Field readers: each refuses with the file, the line and what was expected.

  [[noreturn]] void Fail(const Node& n, const std::string& what) const {
    throw anim::Error(file_ + ":" + std::to_string(n.line) + ": " + what);
  }

  void OnlyKeys(const Node& n, const std::set<std::string>& allowed, const std::string& where) const {
    if (!n.IsMapping()) Fail(n, where + " must be a mapping");
    for (const auto& [k, v] : n.entries)
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(v, "unknown key '" + k + "' in " + where + " (known: " + list + ")");
      }
  }

  double Number(const Node& n, const std::string& what) const {
    if (!n.IsScalar() || n.scalar.empty()) Fail(n, what + ": expected a number");
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(n.scalar, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != n.scalar.size() || !std::isfinite(x)) Fail(n, what + ": expected a number, got '" + n.scalar + "'");
    return x;
  }

  std::string String(const Node& n, const std::string& what) const {
    if (!n.IsScalar() || n.scalar.empty()) Fail(n, what + ": expected a non-empty string");
    return n.scalar;
  }

  std::vector<double> Numbers(const Node& n, const std::string& what, std::size_t count = 0) const {
    if (!n.IsSequence()) Fail(n, what + ": expected a list like [1, 2, 3]");
    if (count && n.items.size() != count)
      Fail(n, what + ": expected " + std::to_string(count) + " numbers, got " + std::to_string(n.items.size()));
    std::vector<double> out;
    for (const Node& x : n.items) out.push_back(Number(x, what));
    return out;
  }

  Eigen::Vector3d Vec3(const Node& n, const std::string& what) const {
    const auto v = Numbers(n, what, 3);
    return {v[0], v[1], v[2]};
  }

  // A direction (anim::UnitDirection): its own line named, and why it gives none.
  Eigen::Vector3d Direction(const Node& n, const std::string& what) const {
    const Eigen::Vector3d v = Vec3(n, what);
    try {
      return anim::UnitDirection(v);
    } catch (const anim::Error& e) {
      Fail(n, what + " " + e.what());
    }
  }

  template <class E>
  E Choice(const Node& n, const std::string& what, const std::vector<std::pair<std::string, E>>& options) const {
    const std::string s = String(n, what);
    std::string list;
    for (const auto& [name, value] : options) {
      if (s == name) return value;
      list += (list.empty() ? "" : " | ") + name;
    }
    Fail(n, what + ": '" + s + "' is not one of " + list);
  }

  bool Bool(const Node& n, const std::string& what) const {
    return Choice<bool>(n, what, {{"true", true}, {"false", false}});
  }

  int Integer(const Node& n, const std::string& what, int lo, int hi) const {
    const double x = Number(n, what);
    if (x != std::floor(x) || x < lo || x > hi)
      Fail(n, what + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
    return static_cast<int>(x);
  }

  double NonNegative(const Node& n, const std::string& what) const {
    const double x = Number(n, what);
    if (x < 0) Fail(n, what + " must not be negative");
    return x;
  }

 private:
  // scene_reader.cpp
  CharacterSpec Character(const Node& n, const std::filesystem::path& base_dir) const;
  std::vector<LineSpec> Lines(const Node& n) const;
  LineSpec Line(const Node& n) const;
  GazeSpec GazeOf(const Node& n) const;
  Anchor AnchorOf(const Node& n) const;
  GestureSpec GestureOf(const Node& n) const;
  KeySpec Key(const Node& n, const CharacterSpec& c) const;
  // scene_schedule_reader.cpp
  anim::ScopeTable Scopes(const Node& n) const;
  IdleSpec Idle(const Node& n, const std::filesystem::path& base_dir) const;
  BalanceSpec Balance(const Node& n, const std::filesystem::path& base_dir, int idle_components) const;
  anim::Curve CurveOf(const Node& n, const std::string& what) const;
  std::vector<anim::Curve> Curves(const Node& n, const std::string& what) const;
  // A mask weight: a number (rotation and translation alike) or {rotation: r, translation: t}.
  std::pair<double, double> MaskWeight(const Node& n, const std::string& what) const;
  MaskSpec MaskOf(const Node& n) const;
  ObjectSpec ObjectOf(const Node& n) const;
  ActionSpec ActionOf(const Node& n) const;
  ScheduleSpec ScheduleOf(const Node& n) const;

  std::string file_;
};

}  // namespace arview::authoring
