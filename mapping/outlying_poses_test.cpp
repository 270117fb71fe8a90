// Outlying poses posed again (mapping/outlying_poses.h) on a made-up model: points seen exactly
// by ten cameras, one of whose poses is then moved off as a bundle adjustment can leave one.

#include "mapping/outlying_poses.h"

#include <gtest/gtest.h>

#include <random>

namespace arview::mapping {
namespace {

// 300 points in a box 3-6 m in front of ten cameras side by side, every point observed by each
// camera that sees it in its 640x480 image, the observations with noise of 0.2 px.
SparseModel ExactModel() {
  SparseModel model;
  model.camera = calib::Camera::Pinhole(640, 480, 500, 500, 320, 240);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> x(-2, 2), y(-1.5, 1.5), z(3, 6);
  std::normal_distribution<double> noise(0, 0.2);
  for (std::uint64_t id = 1; id <= 300; ++id) {
    ColmapPoint p;
    p.id = id;
    p.point.xyz = {x(rng), y(rng), z(rng)};
    model.points.push_back(p);
  }
  for (std::uint32_t i = 0; i < 10; ++i) {
    ColmapImage image;
    image.id = i + 1;
    image.camera_id = 1;
    image.name = "frames/" + std::to_string(i) + ".png";
    image.pose = calib::Pose::FromCameraToWorld(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d::UnitY())), {0.1 * i, 0, 0});
    for (ColmapPoint& p : model.points) {
      const Eigen::Vector3d c = image.pose.ToCamera(p.point.xyz);
      const Eigen::Vector2d px = model.camera.Project(c);
      if (c.z() <= 0 || !model.camera.InImage(px)) continue;
      p.track.push_back({image.id, static_cast<std::uint32_t>(image.xy.size())});
      image.xy.emplace_back(px.x() + 0.5 + noise(rng), px.y() + 0.5 + noise(rng));  // COLMAP's pixel centre at 0.5
      image.point3d_ids.push_back(p.id);
    }
    model.images.push_back(image);
  }
  return model;
}

TEST(OutlyingPoses, APoseLeftOffIsPosedAgainOnItsPointsAndTheOthersAreLeftAlone) {
  SparseModel model = ExactModel();
  const calib::Pose truth = model.images[4].pose;
  // 4 cm along the camera's x and a tenth of a degree: about 3 px off at these depths.
  model.images[4].pose = calib::Pose::FromCameraToWorld(
      truth.CameraToWorldRotation() * Eigen::Quaterniond(Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitX())),
      truth.Center() + Eigen::Vector3d(0.04, 0, 0));
  const SparseModel before = model;
  const std::vector<RePosedImage> re_posed = RePoseOutlyingImages(&model);
  ASSERT_EQ(re_posed.size(), 1u);
  EXPECT_EQ(re_posed[0].name, "frames/4.png");
  EXPECT_TRUE(re_posed[0].kept);
  EXPECT_GT(re_posed[0].median_before_px, 1.0);
  EXPECT_LT(re_posed[0].median_after_px, 0.3);
  EXPECT_LT((model.images[4].pose.Center() - truth.Center()).norm(), 0.005) << "within 5 mm of the truth again";
  for (std::size_t i = 0; i < model.images.size(); ++i) {
    if (i == 4) continue;
    EXPECT_EQ(model.images[i].pose.t_cw, before.images[i].pose.t_cw) << model.images[i].name;
  }
  EXPECT_EQ(Describe(re_posed[0]).rfind("frames/4.png: its ", 0), 0u) << Describe(re_posed[0]);
  EXPECT_TRUE(RePoseOutlyingImages(&model).empty()) << "posed again, it is no longer outlying";
}

TEST(OutlyingPoses, AModelThatFitsEverywhereIsLeftAsItIs) {
  SparseModel model = ExactModel();
  EXPECT_TRUE(RePoseOutlyingImages(&model).empty());
  OutlyingPoseOptions bad;
  bad.keep_below_share = 0;
  EXPECT_THROW(RePoseOutlyingImages(&model, bad), OptionError);
}

}  // namespace
}  // namespace arview::mapping
