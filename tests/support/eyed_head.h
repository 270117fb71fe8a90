#pragma once
// A head with two eyes and their lids, facing +Z (y up), every rest rotation the identity: the
// smallest skeleton gaze (anim/gaze.h) poses, for its tests.

#include "anim/character.h"

#include <Eigen/Core>

namespace arview::testing {

inline anim::Skeleton EyedHead() {
  anim::Skeleton sk;
  sk.names = {"Head", "LeftEye", "LeftUpperLid", "LeftLowerLid", "RightEye", "RightUpperLid", "RightLowerLid"};
  sk.parents = {-1, 0, 0, 0, 0, 0, 0};
  sk.rest.resize(sk.names.size());
  sk.rest[0].translation = {0, 1.6, 0};
  for (int j = 1; j < 7; ++j) sk.rest[j].translation = {j < 4 ? 0.03 : -0.03, 0.03, 0.09};  // the eyes' centre
  sk.inverse_bind.assign(sk.names.size(), Eigen::Matrix4d::Identity());
  return sk;
}

}  // namespace arview::testing
