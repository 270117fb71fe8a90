#pragma once
// The demo's walk through the synthetic room (`arview synth room --path orbit`): two laps round
// a spot on the floor where a character will stand, at 30 fps, hand-held.
//
// - Lap 1 (the first half, mapped): a ring round the spot at 1.6–2.6 m, looking across the room
//   toward the spot while panning ±40°, so the walls, boxes and floor beyond it are seen from
//   every side (the ring is shaped by the room: 0.45 m or more from every wall, 0.35 m or more
//   from every box).
// - Lap 2 (the second half, tracked): the same ring, looking at the character (its chest, its
//   head when close) with a hand-held wobble; it passes behind it, glances away once (a fast
//   50° turn and back, the "fast turn" that tests the tracker), and once walks up to 1.15 m in
//   front of it and lingers before walking on (a greeting distance).
//
// World frame as in synth_room.h (metres, z up, floor z = 0).

#include <Eigen/Core>

#include <cstdint>

#include "calib/pose.h"

namespace arview::synth {

// The pose of a camera at `centre` (world, z up) looking along yaw (about z, from +x) and pitch
// (up from the horizon), rolled by `roll` about its optical axis; radians. Both walks use it.
calib::Pose HandHeldCameraPose(const Eigen::Vector3d& centre, double yaw, double pitch, double roll);

struct OrbitWalkOptions {
  Eigen::Vector2d subject{-0.2, 0.25};  // the spot the laps circle, on the floor
  double start_azimuth_deg = 90;        // where lap 1 starts, seen from the subject (0 = +x)
  double close_fraction = 0.62;         // when in lap 2 the close approach is nearest
  double close_distance = 1.15;         // metres, nearest approach
  double glance_fraction = 0.30;        // when in lap 2 the glance away starts
};

class OrbitWalk {
 public:
  OrbitWalk(double duration, uint64_t seed, const OrbitWalkOptions& options = {});
  // Camera pose (world → camera) at time t seconds.
  calib::Pose At(double t) const;
  // Horizontal distance from the subject's vertical axis to the ring at `azimuth` (radians).
  double RingRadius(double azimuth) const;
  // The subject's position on the floor (z = 0).
  Eigen::Vector3d Subject() const { return {options_.subject.x(), options_.subject.y(), 0}; }
  // Azimuth (radians, from the subject) of the camera at the nearest point of lap 2: the
  // direction a character should face to greet the viewer.
  double CloseApproachAzimuth() const;
  const OrbitWalkOptions& options() const { return options_; }

 private:
  double LapTwoAzimuth(double fraction) const;

  double duration_;
  OrbitWalkOptions options_;
  double pan_phase_, pitch_phase_, roll_phase_, bob_phase_, glance_sign_;
  double shake_phase_[6];
};

}  // namespace arview::synth
