#include "anim/blending_params.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace arview::anim {
namespace {

// Smooth step of the cosine pieces: 0 → 1 on [0, 1] with zero slope at both ends.
double CosineStep(double x) { return 0.5 * (1 - std::cos(M_PI * std::clamp(x, 0.0, 1.0))); }

double Ramp(double x, bool cosine) { return cosine ? CosineStep(x) : std::clamp(x, 0.0, 1.0); }

bool Finite(double x) { return std::isfinite(x); }

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

double Curve::Value(double t, double length) const {
  if (!(t >= 0) || t > length) return 0;
  const bool bounded = Finite(length);
  const double unit = in_seconds || !bounded ? 1.0 : length;
  const bool cosine = shape == Shape::kCosineFade || shape == Shape::kCosineAdsr;
  switch (shape) {
    case Shape::kConstant:
      return peak;
    case Shape::kLinearFade:
    case Shape::kCosineFade: {
      const double in = fade_in * unit, out = fade_out * unit;
      const double up = in > 0 ? Ramp(t / in, cosine) : 1.0;
      const double down = bounded && out > 0 ? Ramp((length - t) / out, cosine) : 1.0;
      return peak * std::min(up, down);
    }
    case Shape::kAdsr:
    case Shape::kCosineAdsr: {
      const double a = attack * unit, d = decay * unit, r = release * unit;
      if (t < a) return peak * Ramp(t / a, cosine);
      if (t < a + d) return peak * (1 - (1 - sustain) * Ramp((t - a) / d, cosine));
      if (bounded && r > 0 && t > length - r) return peak * sustain * Ramp((length - t) / r, cosine);
      return peak * sustain;
    }
  }
  return 0;
}

std::string Curve::Check(double length) const {
  for (double x : {fade_in, fade_out, attack, decay, release, peak, sustain})
    if (!Finite(x) || x < 0) return "curve lengths and levels must be finite and non-negative";
  if (sustain > 1) return "sustain is a fraction of the peak, at most 1";
  const bool bounded = Finite(length);
  const double total = shape == Shape::kLinearFade || shape == Shape::kCosineFade ? fade_in + fade_out
                       : shape == Shape::kAdsr || shape == Shape::kCosineAdsr  ? attack + decay + release
                                                                               : 0.0;
  if (!bounded && !in_seconds && total > 0)
    return "an unbounded action (no fixed length) needs its curve lengths in seconds";
  if (!bounded && in_seconds && (fade_out > 0 || release > 0))
    return "an unbounded action has no end to fade out or release toward";
  const double limit = in_seconds ? length : 1.0;
  if (bounded && total > limit * (1 + 1e-12))
    return in_seconds ? "curve pieces are longer than the action" : "curve fractions add up to more than 1";
  return {};
}

void JointMask::SetRotation(const std::vector<int>& joints, double weight) {
  for (int j : joints) rotation.at(j) = weight;
}
void JointMask::SetTranslation(const std::vector<int>& joints, double weight) {
  for (int j : joints) translation.at(j) = weight;
}

std::vector<int> Subtree(const Skeleton& skeleton, int joint) {
  std::vector<int> out;
  std::vector<bool> in(skeleton.size(), false);
  in[joint] = true;
  out.push_back(joint);
  // Parents come before children: one forward pass collects the descendants.
  for (int j = joint + 1; j < skeleton.size(); ++j)
    if (skeleton.parents[j] >= 0 && in[skeleton.parents[j]]) {
      in[j] = true;
      out.push_back(j);
    }
  return out;
}

namespace {

enum class Side { kLeft, kRight, kNone };

// Left/right from a joint name: "Left"/"Right" words, "_L"/"_R", ".L", "L_" prefixes, and
// CMU's one-letter prefixes before a body-part word ("lhumerus", "LThumb").
Side SideOf(const std::string& name) {
  const std::string n = Lower(name);
  if (n.find("left") != std::string::npos) return Side::kLeft;
  if (n.find("right") != std::string::npos) return Side::kRight;
  auto has_marker = [&](char s) {
    const std::string up(1, static_cast<char>(std::toupper(s)));
    for (const std::string& m : {std::string("_") + s, std::string(".") + s, std::string(1, s) + "_"}) {
      const auto at = n.find(m);
      if (at == std::string::npos) continue;
      const std::size_t letter = m[0] == s ? at : at + 1;
      const bool before_ok = letter == 0 || !std::isalpha(static_cast<unsigned char>(n[letter - 1]));
      const bool after_ok = letter + 1 >= n.size() || !std::isalpha(static_cast<unsigned char>(n[letter + 1]));
      if (before_ok && after_ok) return true;
    }
    // "LThumb", "RHipJoint": an upper-case side letter followed by an upper-case word start.
    return name.size() > 2 && name.substr(0, 1) == up && std::isupper(static_cast<unsigned char>(name[1])) &&
           std::islower(static_cast<unsigned char>(name[2]));
  };
  if (has_marker('l')) return Side::kLeft;
  if (has_marker('r')) return Side::kRight;
  return Side::kNone;
}

bool NameHas(const std::string& name, std::initializer_list<const char*> words) {
  const std::string n = Lower(name);
  for (const char* w : words)
    if (n.find(w) != std::string::npos) return true;
  return false;
}

// The first joint matching the earliest word of `words` (in priority order; joints in
// parent-before-child order) whose side is `side`, or −1. A word starting with '=' must match
// the whole (lower-case) name.
int FirstJoint(const Skeleton& sk, std::initializer_list<const char*> words, Side side) {
  for (const char* w : words)
    for (int j = 0; j < sk.size(); ++j) {
      const bool match = w[0] == '=' ? Lower(sk.names[j]) == w + 1 : NameHas(sk.names[j], {w});
      if (match && (side == Side::kNone || SideOf(sk.names[j]) == side)) return j;
    }
  return -1;
}

int ArmRootOf(const Skeleton& sk, Side side) {
  int j = FirstJoint(sk, {"clavicle", "collar"}, side);
  if (j < 0) j = FirstJoint(sk, {"shoulder"}, side);
  if (j < 0) j = FirstJoint(sk, {"upperarm", "humerus", "arm"}, side);
  return j;
}

int LegRootOf(const Skeleton& sk, Side side) {
  int j = FirstJoint(sk, {"hipjoint", "upleg", "thigh", "femur", "hip"}, side);
  if (j < 0) j = FirstJoint(sk, {"leg", "knee"}, side);
  return j;
}

std::vector<int> Join(std::vector<int> a, const std::vector<int>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  return a;
}

}  // namespace

int ArmRoot(const Skeleton& sk, bool left) { return ArmRootOf(sk, left ? Side::kLeft : Side::kRight); }
int LegRoot(const Skeleton& sk, bool left) { return LegRootOf(sk, left ? Side::kLeft : Side::kRight); }
int NeckJoint(const Skeleton& sk) {
  const int j = FirstJoint(sk, {"neck"}, Side::kNone);
  return j >= 0 ? j : FirstJoint(sk, {"head"}, Side::kNone);
}
int NameSide(const std::string& name) {
  const Side s = SideOf(name);
  return s == Side::kLeft ? 1 : s == Side::kRight ? -1 : 0;
}

const std::vector<std::string>& BuiltinScopes() {
  static const std::vector<std::string> names = {"all", "root", "torso", "legs", "left_leg", "right_leg",
                                                 "left_arm", "right_arm", "head"};
  return names;
}

std::vector<int> ResolveScope(const Skeleton& sk, const std::string& name, const ScopeTable& custom) {
  if (const auto it = custom.find(name); it != custom.end()) {
    std::vector<int> out;
    for (const std::string& joint : it->second.joints) {
      const int j = sk.Find(joint);
      if (j < 0) throw Error("scope '" + name + "': no joint named '" + joint + "' in the skeleton");
      out = Join(std::move(out), it->second.descendants ? Subtree(sk, j) : std::vector<int>{j});
    }
    return out;
  }
  auto need = [&](int j, const char* what) {
    if (j < 0) throw Error("scope '" + name + "': no " + what + " joint found by name in this skeleton (define it under 'scopes:')");
    return Subtree(sk, j);
  };
  if (name == "all") {
    std::vector<int> out(sk.size());
    for (int j = 0; j < sk.size(); ++j) out[j] = j;
    return out;
  }
  if (name == "root") return {0};
  if (name == "torso") {
    int j = FirstJoint(sk, {"lowerback", "spine", "=ab", "abdomen", "chest", "back"}, Side::kNone);
    if (j < 0) {
      // Rigs that name no spine (CesiumMan: torso_joint_1 > _2 > _3 > neck): the neck's
      // ancestor just below the root.
      for (int k = NeckJoint(sk); k >= 0 && sk.parents[k] >= 0; k = sk.parents[k]) j = k;
      if (j >= 0 && j == NeckJoint(sk)) j = -1;
    }
    return need(j, "spine");
  }
  if (name == "head") return need(NeckJoint(sk), "neck or head");
  if (name == "left_arm") return need(ArmRootOf(sk, Side::kLeft), "left shoulder/arm");
  if (name == "right_arm") return need(ArmRootOf(sk, Side::kRight), "right shoulder/arm");
  if (name == "left_leg") return need(LegRootOf(sk, Side::kLeft), "left hip/leg");
  if (name == "right_leg") return need(LegRootOf(sk, Side::kRight), "right hip/leg");
  if (name == "legs") return Join(need(LegRootOf(sk, Side::kLeft), "left hip/leg"), need(LegRootOf(sk, Side::kRight), "right hip/leg"));
  std::string known;
  for (const auto& s : BuiltinScopes()) known += (known.empty() ? "" : ", ") + s;
  for (const auto& [n, s] : custom) known += ", " + n;
  throw Error("unknown scope '" + name + "' (known: " + known + ")");
}

double BlendingParams::TimeWeight(double t, double length) const {
  double w = gain;
  for (const Curve& c : curves) w *= c.Value(t, length);
  return w;
}

double BlendingParams::Scaling(double t, double length) const {
  double s = 1;
  for (const Curve& c : scalings) s *= c.Value(t, length);
  return s;
}

double BlendingParams::MaskRotation(int j) const {
  double w = 1;
  for (const JointMask& m : masks) w *= m.rotation[j];
  return w;
}

double BlendingParams::MaskTranslation(int j) const {
  double w = 1;
  for (const JointMask& m : masks) w *= m.translation[j];
  return w;
}

}  // namespace arview::anim
