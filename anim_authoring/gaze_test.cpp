// The paper's claim, checked on real rigs: with key animations that look toward 8 viewpoints
// around the horizon, the blended character's head points at viewpoints between the keys.

#include "anim_authoring/character_builder.h"
#include "anim_authoring/scene.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;

struct GazeStats {
  double median_deg = 0, max_deg = 0;
  int samples = 0;
};

// Viewpoints at `elevation` degrees, at azimuths between the keys (10°, 22.5° and 35° past each).
GazeStats MeasureGaze(const fs::path& asset, const std::string& method, const std::string& mode, double elevation) {
  std::string text = "characters:\n  - asset: " + asset.string() + "\n    blend: {method: " + method +
                     "}\n    weights: {mode: " + mode + "}\n    keys:\n";
  for (int k = 0; k < 8; ++k) text += "      - azimuth: " + std::to_string(45 * k) + "\n        generate: lookat\n";
  const Scene scene = ParseScene(text, "gaze.yaml");
  AnimatedCharacter ch(scene.characters[0]);
  const anim::LookAtChain& chain = ch.lookat_chain();
  std::vector<double> angles;
  for (int k = 0; k < 8; ++k)
    for (double offset : {10.0, 22.5, 35.0})
      for (double t : {0.0, 0.37, 0.81, 1.6, 2.9}) {
        const Eigen::Vector3d v = anim::DirectionFromAzimuthElevation(45 * k + offset, elevation);
        const anim::AnimatorFrame& out = ch.Update(v, t);
        EXPECT_TRUE(out.converged);
        const Eigen::Vector3d f = anim::HeadForward(chain, out.model);
        angles.push_back(std::atan2(f.cross(v).norm(), f.dot(v)) * 180 / M_PI);
      }
  std::sort(angles.begin(), angles.end());
  GazeStats s;
  s.samples = static_cast<int>(angles.size());
  s.median_deg = angles[angles.size() / 2];
  s.max_deg = angles.back();
  std::printf("[gaze] %s %s %s elevation %.0f: %d viewpoints x times, head-to-viewpoint angle median %.2f deg, max %.2f deg\n",
              asset.filename().c_str(), method.c_str(), mode.c_str(), elevation, s.samples, s.median_deg, s.max_deg);
  return s;
}

void CheckGaze(const fs::path& asset) {
  for (const char* method : {"dlb", "dib"})
    for (const char* mode : {"inverse-distance", "local"}) {
      const GazeStats s = MeasureGaze(asset, method, mode, 0.0);
      EXPECT_LE(s.max_deg, 15.0) << asset << " " << method << " " << mode;
      // Above the keys' ring no key looks up: the head stays level, so the error is about the
      // elevation itself. Reported, bounded loosely.
      const GazeStats above = MeasureGaze(asset, method, mode, 10.0);
      EXPECT_LE(above.max_deg, 25.0) << asset << " " << method << " " << mode;
      ::testing::Test::RecordProperty(std::string("median_deg_") + method + "_" + mode, std::to_string(s.median_deg));
      ::testing::Test::RecordProperty(std::string("max_deg_") + method + "_" + mode, std::to_string(s.max_deg));
    }
}

TEST(Gaze, Fox) {
  const fs::path fox = testing::SharedData("characters/Fox/glTF-Binary/Fox.glb");
  ARVIEW_REQUIRE_DATA_PATH(fox, "../shared/data");
  CheckGaze(fox);
}

TEST(Gaze, BcnEpileptic) {
  const fs::path bcn = "/usr/share/assimp/models/X/BCN_Epileptic.X";
  ARVIEW_REQUIRE_DATA_PATH(bcn, "Debian package assimp-testmodels");
  CheckGaze(bcn);
}

TEST(Gaze, KeyViewpointIsMetExactly) {
  const fs::path fox = testing::SharedData("characters/Fox/glTF-Binary/Fox.glb");
  ARVIEW_REQUIRE_DATA_PATH(fox, "../shared/data");
  const Scene scene = ParseScene("characters:\n  - asset: " + fox.string() +
                                     "\n    keys:\n      - azimuth: 0\n        generate: lookat\n"
                                     "      - azimuth: 135\n        generate: lookat\n",
                                 "gaze.yaml");
  AnimatedCharacter ch(scene.characters[0]);
  const Eigen::Vector3d v = anim::DirectionFromAzimuthElevation(135, 0);
  const Eigen::Vector3d f = anim::HeadForward(ch.lookat_chain(), ch.Update(v, 0.5).model);
  EXPECT_GT(f.dot(v), std::cos(0.5 * M_PI / 180));
}

}  // namespace
}  // namespace arview::authoring
