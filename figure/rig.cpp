#include "figure/rig.h"

namespace arview::figure {

Rig BuildRig() {
  Rig r;
  r.Add("Hips", "", {0, 0.96, 0});
  r.Add("Spine", "Hips", {0, 1.06, 0});
  r.Add("Spine1", "Spine", {0, 1.18, 0});
  r.Add("Spine2", "Spine1", {0, 1.30, 0});
  r.Add("Neck", "Spine2", {0, 1.45, 0});
  r.Add("Head", "Neck", {0, 1.54, 0});
  r.Add("HeadTop_End", "Head", {0, 1.745, 0});
  for (int side : {1, -1}) {
    const Vector3d d = ArmDirection(side);
    const Vector3d shoulder(side * 0.175, 1.405, 0);
    r.Add(Sided(side, "Shoulder"), "Spine2", {side * 0.03, 1.40, 0});
    r.Add(Sided(side, "Arm"), Sided(side, "Shoulder"), shoulder);
    r.Add(Sided(side, "ForeArm"), Sided(side, "Arm"), shoulder + 0.28 * d);
    r.Add(Sided(side, "Hand"), Sided(side, "ForeArm"), shoulder + 0.53 * d);
    r.Add(Sided(side, "HandIndex1"), Sided(side, "Hand"), shoulder + 0.63 * d);
    r.Add(Sided(side, "HandThumb1"), Sided(side, "Hand"), shoulder + 0.55 * d + Vector3d(0, 0, 0.025));
  }
  for (int side : {1, -1}) {
    r.Add(Sided(side, "UpLeg"), "Hips", {side * 0.09, 0.92, 0});
    r.Add(Sided(side, "Leg"), Sided(side, "UpLeg"), {side * 0.09, 0.50, 0.012});
    r.Add(Sided(side, "Foot"), Sided(side, "Leg"), {side * 0.09, 0.085, -0.005});
    r.Add(Sided(side, "ToeBase"), Sided(side, "Foot"), {side * 0.09, 0.03, 0.12});
    r.Add(Sided(side, "Toe_End"), Sided(side, "ToeBase"), {side * 0.09, 0.03, 0.185});
  }
  AddFaceJoints(r);
  return r;
}

void AddFaceJoints(Rig& r) {
  // After the body's joints, so that their indices stay what they were before the face had
  // joints. The eyes, lids and brows hang from the head; each lid turns about its eye's centre.
  const Vector3d c = HeadCentre(r);
  for (int side : {1, -1}) {
    const Vector3d eye = c + kEyeOffset.cwiseProduct(Vector3d(side, 1, 1));
    r.Add(Sided(side, "Eye"), "Head", eye);
    r.Add(Sided(side, "UpperLid"), "Head", eye);
    r.Add(Sided(side, "LowerLid"), "Head", eye);
    r.Add(Sided(side, "Brow"), "Head", c + Vector3d(side * 0.033, 0.040, 0.080));
  }
  r.Add("Jaw", "Head", c + kJawOffset);
}

}  // namespace arview::figure
