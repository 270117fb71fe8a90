#pragma once
// The built-in figure's morph targets (issue 52): ARKit-named face shapes, the 15 visemes of
// Meta/OpenXR and Ekman's six expressions as weights of the ARKit ones. The targets move only
// the face's small meshes (lips, mouth, brows, the lids' skin) and the head's skin (cheeks and
// chin), so a weighted target costs a few hundred vertices (docs/figure.md "Morph targets").
//
//   const anim::Character c = MakeHumanoid();              // has every target below
//   for (const TargetWeight& w : ExpressionWeights(Expression::kHappy, 0.7))
//     weights[c.skeleton.FindMorphTarget(w.target)] = w.weight;

#include <span>
#include <string>
#include <vector>

namespace arview::figure {

// The ARKit blendshape names the figure has, in the order they are added (the first targets).
std::span<const char* const> ArkitTargetNames();
// viseme_sil viseme_PP ... viseme_ou, in Meta/OpenXR's order, after the ARKit ones.
std::span<const char* const> VisemeTargetNames();

// The angle jawOpen turns the chin about the Jaw joint's pivot at weight 1, degrees.
inline constexpr double kJawOpenDegrees = 14;
// Each viseme target's jaw opening as a share of jawOpen, in VisemeTargetNames' order (the
// table's jawOpen column in docs/figure.md): what a speech layer that turns the Jaw joint takes
// out of the targets and turns the joint by instead (anim/face.h).
std::span<const float> VisemeJawShares();

enum class Expression { kHappy, kSad, kAngry, kSurprised, kAfraid, kDisgusted };
inline constexpr Expression kExpressions[] = {Expression::kHappy,     Expression::kSad,    Expression::kAngry,
                                              Expression::kSurprised, Expression::kAfraid, Expression::kDisgusted};
// "happy", "sad", "angry", "surprised", "afraid", "disgusted".
const char* ExpressionName(Expression expression);

struct TargetWeight {
  const char* target;  // an ARKit target's name
  float weight;        // in [0, 1]
};
// The ARKit target weights that show `expression` at `intensity` (clamped to [0, 1]): the table
// in docs/figure.md scaled by the intensity. The jaw's share is the jawOpen target, not the Jaw
// joint (which gaze and clips leave at rest): a layer that also turns the Jaw joint opens the
// mouth by both.
std::vector<TargetWeight> ExpressionWeights(Expression expression, double intensity);

}  // namespace arview::figure
