#include "figure/face_targets.h"

#include "figure/rig.h"

#include "anim/morph.h"

#include <array>
#include <functional>

namespace arview::figure {
namespace {

// ---------------------------------------------------------------------------------------------
// A target is a displacement of each rest vertex, written in the head's frame (q = p − the
// head's centre; +X the figure's left, +Y up, +Z forward) from what the vertex belongs to.

enum class Part { kUpperLip, kLowerLip, kMouth, kBrow, kHeadSkin, kUpperLid, kLowerLid };

struct FaceVertex {
  Part part;
  Vector3d q;          // rest position relative to HeadCentre
  double jaw = 0;      // the Jaw joint's skinning weight
  Vector3d eye_centre = Vector3d::Zero();  // for lid vertices, relative to HeadCentre
};

using Move = std::function<Vector3d(const FaceVertex&)>;

constexpr double kMm = 0.001;
constexpr double kJawOpenDeg = kJawOpenDegrees;  // jawOpen at weight 1: the chin turned about the jaw's pivot
constexpr double kLipHalfWidth = 0.023;

double Side(const FaceVertex& v) { return v.q.x() >= 0 ? 1 : -1; }
bool IsLip(const FaceVertex& v) { return v.part == Part::kUpperLip || v.part == Part::kLowerLip || v.part == Part::kMouth; }
// 0 at the mouth's middle, 1 at its corners (lips and the mouth's dark).
double Corner(const FaceVertex& v) { return IsLip(v) ? SmoothStep(std::abs(v.q.x()) / kLipHalfWidth) : 0; }
// 1 on the `side` half of the mouth, 0 on the other (the middle moves half).
double OnSide(const FaceVertex& v, int side) { return SmoothStep(0.5 + side * v.q.x() / 0.012); }
// The cheek over the mouth's corner on `side`: 1 at its centre, 0 beyond 3 cm (clear of the nose).
double Cheek(const FaceVertex& v, int side) {
  if (v.part != Part::kHeadSkin) return 0;
  return SmoothStep(1 - (v.q - Vector3d(side * 0.048, -0.035, 0.065)).norm() / 0.03);
}

// The jaw's opening as geometry: the vertices the Jaw joint moves, turned about its pivot by
// their jaw weight, and the mouth's dark stretched down into the opening.
Vector3d JawOpen(const FaceVertex& v) {
  const Vector3d pivot = kJawOffset;
  const Vector3d turned = pivot + Rx(kJawOpenDeg) * (v.q - pivot);
  Vector3d d = v.jaw * (turned - v.q);
  if (v.part == Part::kMouth) {
    const Vector3d lower_lip(0, -0.0545, 0.082);
    const Vector3d lip_drop = pivot + Rx(kJawOpenDeg) * (lower_lip - pivot) - lower_lip;
    d = lip_drop * SmoothStep((-0.046 - v.q.y()) / 0.008) + Vector3d(0, 0, 5 * kMm);
  }
  return d;
}
// The lower lip back up onto the upper one whatever jawOpen did (ARKit: mouthClose with jawOpen).
Vector3d MouthClose(const FaceVertex& v) { return v.part == Part::kLowerLip ? Vector3d(-JawOpen(v)) : Vector3d::Zero(); }
// Lips pressed together: each 1 mm toward the other and a little flatter.
Vector3d LipPress(const FaceVertex& v) {
  if (v.part == Part::kUpperLip) return Vector3d(0, -1.2 * kMm, -1 * kMm);
  if (v.part == Part::kLowerLip) return Vector3d(0, 1.2 * kMm, -1 * kMm);
  return Vector3d::Zero();
}
// The lower lip drawn up and back under the upper teeth (FF).
Vector3d LowerLipTuck(const FaceVertex& v) { return v.part == Part::kLowerLip ? Vector3d(0, 2 * kMm, -4 * kMm) : Vector3d::Zero(); }
Vector3d MouthFunnel(const FaceVertex& v) {
  if (!IsLip(v)) return Vector3d::Zero();
  const double open = v.part == Part::kUpperLip ? 2.5 : v.part == Part::kLowerLip ? -2.5 : 0;
  return Vector3d(-0.18 * v.q.x(), open * kMm * (1 - Corner(v)), 4 * kMm);
}
Vector3d MouthPucker(const FaceVertex& v) {
  if (!IsLip(v)) return Vector3d::Zero();
  const double toward = v.part == Part::kUpperLip ? -0.6 : v.part == Part::kLowerLip ? 0.6 : 0;
  return Vector3d(-0.38 * v.q.x(), toward * kMm, 6 * kMm * (1 - 0.5 * Corner(v)));
}
Vector3d MouthSmile(const FaceVertex& v, int side) {
  const double c = Corner(v) * OnSide(v, side);
  return c * Vector3d(side * 4 * kMm, 5 * kMm, -3 * kMm) + Cheek(v, side) * Vector3d(side * 1 * kMm, 3 * kMm, 1.5 * kMm);
}
Vector3d MouthFrown(const FaceVertex& v, int side) { return Corner(v) * OnSide(v, side) * Vector3d(side * 1 * kMm, -6 * kMm, 0); }
Vector3d MouthStretch(const FaceVertex& v, int side) {
  return Corner(v) * OnSide(v, side) * Vector3d(side * 6 * kMm, -1.5 * kMm, -1 * kMm);
}
// The upper lip's side raised off the teeth (disgust).
Vector3d MouthUpperUp(const FaceVertex& v, int side) {
  return v.part == Part::kUpperLip ? Vector3d(0, 3 * kMm * OnSide(v, side) * (1 - 0.6 * Corner(v)), 0.5 * kMm) : Vector3d::Zero();
}
// Along a brow: 1 at its inner end (by the nose), 0 at its outer end.
double BrowInner(const FaceVertex& v) { return 1 - SmoothStep((std::abs(v.q.x()) - 0.014) / 0.038); }
Vector3d BrowInnerUp(const FaceVertex& v) { return v.part == Part::kBrow ? Vector3d(0, 6 * kMm * BrowInner(v), 0) : Vector3d::Zero(); }
Vector3d BrowOuterUp(const FaceVertex& v, int side) {
  return v.part == Part::kBrow && Side(v) == side ? Vector3d(0, 5 * kMm * (1 - BrowInner(v)), 0) : Vector3d::Zero();
}
Vector3d BrowDown(const FaceVertex& v, int side) {
  if (v.part != Part::kBrow || Side(v) != side) return Vector3d::Zero();
  return Vector3d(-side * 2 * kMm * BrowInner(v), -(2 + 3 * BrowInner(v)) * kMm, 0.5 * kMm);
}
Vector3d CheekPuff(const FaceVertex& v) {
  const double c = std::max(Cheek(v, 1), Cheek(v, -1));
  return c * Vector3d(Side(v) * 5 * kMm, 0, 3 * kMm);
}
// The lower lid raised over the eye (turned 20° about the eye's centre) and the cheek below it.
Vector3d EyeSquint(const FaceVertex& v, int side) {
  if (v.part == Part::kLowerLid && Side(v) == side) {
    const Vector3d r = v.q - v.eye_centre;
    return Rx(-20) * r - r;
  }
  return Cheek(v, side) * Vector3d(0, 2 * kMm, 0.5 * kMm);
}

// ---------------------------------------------------------------------------------------------
// The targets, in order: the ARKit ones, then the visemes, each a sum of weighted moves.

struct Term {
  Move move;
  double weight;
};
struct TargetSpec {
  const char* name;
  std::vector<Term> terms;
};

Move ForSide(Vector3d (*f)(const FaceVertex&, int), int side) {
  return [f, side](const FaceVertex& v) { return f(v, side); };
}

const std::vector<TargetSpec>& ArkitTargets() {
  static const std::vector<TargetSpec> targets = {
      {"jawOpen", {{JawOpen, 1}}},
      {"mouthClose", {{MouthClose, 1}}},
      {"mouthFunnel", {{MouthFunnel, 1}}},
      {"mouthPucker", {{MouthPucker, 1}}},
      {"mouthSmileLeft", {{ForSide(MouthSmile, 1), 1}}},
      {"mouthSmileRight", {{ForSide(MouthSmile, -1), 1}}},
      {"mouthFrownLeft", {{ForSide(MouthFrown, 1), 1}}},
      {"mouthFrownRight", {{ForSide(MouthFrown, -1), 1}}},
      {"mouthStretchLeft", {{ForSide(MouthStretch, 1), 1}}},
      {"mouthStretchRight", {{ForSide(MouthStretch, -1), 1}}},
      {"mouthUpperUpLeft", {{ForSide(MouthUpperUp, 1), 1}}},
      {"mouthUpperUpRight", {{ForSide(MouthUpperUp, -1), 1}}},
      {"browInnerUp", {{BrowInnerUp, 1}}},
      {"browOuterUpLeft", {{ForSide(BrowOuterUp, 1), 1}}},
      {"browOuterUpRight", {{ForSide(BrowOuterUp, -1), 1}}},
      {"browDownLeft", {{ForSide(BrowDown, 1), 1}}},
      {"browDownRight", {{ForSide(BrowDown, -1), 1}}},
      {"cheekPuff", {{CheekPuff, 1}}},
      {"eyeSquintLeft", {{ForSide(EyeSquint, 1), 1}}},
      {"eyeSquintRight", {{ForSide(EyeSquint, -1), 1}}},
  };
  return targets;
}

Vector3d Stretch(const FaceVertex& v) { return MouthStretch(v, 1) + MouthStretch(v, -1); }
Vector3d Smile(const FaceVertex& v) { return MouthSmile(v, 1) + MouthSmile(v, -1); }

// The visemes as mouth shapes (no tongue or teeth to show): how far the jaw opens, and how the
// lips press, tuck, round, push forward or spread. docs/figure.md has the same table.
const std::vector<TargetSpec>& VisemeTargets() {
  static const std::vector<TargetSpec> targets = {
      {"viseme_sil", {{LipPress, 0.3}}},
      {"viseme_PP", {{LipPress, 1}}},
      {"viseme_FF", {{JawOpen, 0.15}, {LowerLipTuck, 1}}},
      {"viseme_TH", {{JawOpen, 0.25}, {Stretch, 0.2}}},
      {"viseme_DD", {{JawOpen, 0.3}, {Stretch, 0.3}}},
      {"viseme_kk", {{JawOpen, 0.4}, {Stretch, 0.3}}},
      {"viseme_CH", {{JawOpen, 0.2}, {MouthFunnel, 0.6}, {MouthPucker, 0.2}}},
      {"viseme_SS", {{JawOpen, 0.1}, {Stretch, 0.5}, {Smile, 0.2}}},
      {"viseme_nn", {{JawOpen, 0.2}, {Stretch, 0.2}}},
      {"viseme_RR", {{JawOpen, 0.2}, {MouthFunnel, 0.4}, {MouthPucker, 0.3}}},
      {"viseme_aa", {{JawOpen, 1}}},
      {"viseme_E", {{JawOpen, 0.45}, {Stretch, 0.5}, {Smile, 0.2}}},
      {"viseme_ih", {{JawOpen, 0.3}, {Stretch, 0.6}, {Smile, 0.3}}},
      {"viseme_oh", {{JawOpen, 0.6}, {MouthFunnel, 0.8}}},
      {"viseme_ou", {{JawOpen, 0.25}, {MouthPucker, 1}}},
  };
  return targets;
}

template <const std::vector<TargetSpec>& (*Targets)()>
std::span<const char* const> Names() {
  static const std::vector<const char*> names = [] {
    std::vector<const char*> n;
    for (const TargetSpec& t : Targets()) n.push_back(t.name);
    return n;
  }();
  return names;
}

// What each vertex of a face mesh belongs to; meshes the targets never move are left out.
struct FaceMesh {
  int mesh;
  std::vector<FaceVertex> vertices;
};

std::vector<FaceMesh> FaceMeshes(const Rig& rig, const anim::Character& c) {
  const Vector3d centre = HeadCentre(rig);
  const int jaw = rig.Index("Jaw"), head = rig.Index("Head");
  std::vector<FaceMesh> out;
  for (int m = 0; m < static_cast<int>(c.meshes.size()); ++m) {
    const anim::Mesh& mesh = c.meshes[m];
    const bool lips = mesh.name == "face_lips", mouth = mesh.name == "face_mouth", brows = mesh.name == "face_hair";
    const bool head_skin = mesh.name == "head_skin";
    const int eye_side = mesh.name == "LeftEye_skin" ? 1 : mesh.name == "RightEye_skin" ? -1 : 0;
    if (!lips && !mouth && !brows && !head_skin && eye_side == 0) continue;
    FaceMesh face{m, {}};
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      FaceVertex fv{Part::kHeadSkin, mesh.positions[v].cast<double>() - centre};
      for (int k = 0; k < 4; ++k)
        if (mesh.joints[v][k] == jaw) fv.jaw += mesh.weights[v][k];
      if (lips) fv.part = mesh.joints[v][0] == head && fv.jaw == 0 ? Part::kUpperLip : Part::kLowerLip;
      if (mouth) fv.part = Part::kMouth;
      if (brows) fv.part = Part::kBrow;
      if (eye_side != 0) {
        fv.eye_centre = rig.At(figure::Sided(eye_side, "Eye")) - centre;
        fv.part = fv.q.y() < fv.eye_centre.y() ? Part::kLowerLid : Part::kUpperLid;
      }
      face.vertices.push_back(fv);
    }
    out.push_back(std::move(face));
  }
  return out;
}

void AddTarget(anim::Character& c, const std::vector<FaceMesh>& meshes, const TargetSpec& spec) {
  bool added = false;
  for (const FaceMesh& face : meshes) {
    std::vector<Eigen::Vector3f> deltas(face.vertices.size(), Eigen::Vector3f::Zero());
    bool moves = false;
    for (std::size_t v = 0; v < face.vertices.size(); ++v) {
      Vector3d d = Vector3d::Zero();
      for (const Term& term : spec.terms) d += term.weight * term.move(face.vertices[v]);
      deltas[v] = d.cast<float>();
      moves = moves || deltas[v].norm() > 1e-6f;
    }
    if (!moves) continue;
    for (Eigen::Vector3f& d : deltas)
      if (d.norm() <= 1e-6f) d.setZero();  // below a micrometre: not a vertex the target moves
    anim::AddMorphTarget(c, spec.name, face.mesh, deltas);
    added = true;
  }
  if (!added) throw anim::Error("builtin:figure: internal error: morph target " + std::string(spec.name) + " moves nothing");
}

// Ekman's six as ARKit weights at full intensity (docs/figure.md has the same table).
struct ExpressionSpec {
  Expression expression;
  const char* name;
  std::vector<TargetWeight> weights;
};
const std::vector<ExpressionSpec>& ExpressionTable() {
  static const std::vector<ExpressionSpec> table = {
      {Expression::kHappy, "happy",
       {{"mouthSmileLeft", 0.9f}, {"mouthSmileRight", 0.9f}, {"eyeSquintLeft", 0.5f}, {"eyeSquintRight", 0.5f}, {"jawOpen", 0.1f}}},
      {Expression::kSad, "sad",
       {{"browInnerUp", 0.9f}, {"mouthFrownLeft", 0.8f}, {"mouthFrownRight", 0.8f}, {"mouthClose", 0.2f}}},
      {Expression::kAngry, "angry",
       {{"browDownLeft", 1.0f}, {"browDownRight", 1.0f}, {"eyeSquintLeft", 0.4f}, {"eyeSquintRight", 0.4f},
        {"mouthFrownLeft", 0.4f}, {"mouthFrownRight", 0.4f}}},
      {Expression::kSurprised, "surprised",
       {{"browInnerUp", 1.0f}, {"browOuterUpLeft", 1.0f}, {"browOuterUpRight", 1.0f}, {"jawOpen", 0.6f}, {"mouthFunnel", 0.3f}}},
      {Expression::kAfraid, "afraid",
       {{"browInnerUp", 1.0f}, {"browOuterUpLeft", 0.3f}, {"browOuterUpRight", 0.3f}, {"mouthStretchLeft", 0.8f},
        {"mouthStretchRight", 0.8f}, {"jawOpen", 0.25f}}},
      {Expression::kDisgusted, "disgusted",
       {{"browDownLeft", 0.5f}, {"browDownRight", 0.5f}, {"eyeSquintLeft", 0.6f}, {"eyeSquintRight", 0.6f},
        {"mouthUpperUpLeft", 0.8f}, {"mouthUpperUpRight", 0.8f}, {"mouthFrownLeft", 0.3f}, {"mouthFrownRight", 0.3f}}},
  };
  return table;
}

const ExpressionSpec& Find(Expression expression) {
  for (const ExpressionSpec& e : ExpressionTable())
    if (e.expression == expression) return e;
  throw anim::Error("builtin:figure: internal error: an expression without a table row");
}

}  // namespace

std::span<const char* const> ArkitTargetNames() { return Names<ArkitTargets>(); }
std::span<const char* const> VisemeTargetNames() { return Names<VisemeTargets>(); }

std::span<const float> VisemeJawShares() {
  static const std::vector<float> shares = [] {
    std::vector<float> s;
    for (const TargetSpec& t : VisemeTargets()) {
      float share = 0;
      for (const Term& term : t.terms) {
        const auto* f = term.move.target<Vector3d (*)(const FaceVertex&)>();
        if (f && *f == &JawOpen) share += static_cast<float>(term.weight);
      }
      s.push_back(share);
    }
    return s;
  }();
  return shares;
}

const char* ExpressionName(Expression expression) { return Find(expression).name; }

std::vector<TargetWeight> ExpressionWeights(Expression expression, double intensity) {
  const float scale = static_cast<float>(std::clamp(intensity, 0.0, 1.0));
  std::vector<TargetWeight> out = Find(expression).weights;
  for (TargetWeight& w : out) w.weight *= scale;
  return out;
}

void AddFaceTargets(const Rig& rig, anim::Character& character) {
  const std::vector<FaceMesh> meshes = FaceMeshes(rig, character);
  for (const TargetSpec& spec : ArkitTargets()) AddTarget(character, meshes, spec);
  for (const TargetSpec& spec : VisemeTargets()) AddTarget(character, meshes, spec);
}

}  // namespace arview::figure
