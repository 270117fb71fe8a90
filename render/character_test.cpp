// The skinned character: GPU skinning (DQ and LBS) against anim/'s CPU skinning, compositing,
// side-by-side stereo.

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "anim_authoring/character_builder.h"
#include "anim_authoring/scene.h"
#include "render/ar_renderer.h"
#include "render/render_error.h"
#include "render/test_scene.h"
#include "tests/support/fox_view.h"
#include "tests/support/test_data.h"

namespace arview::render {
namespace {

namespace fs = std::filesystem;

fs::path Fox() { return arview::testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"); }

authoring::Scene FoxScene() { return authoring::ParseScene(arview::testing::FoxSceneYaml(), "fox_test.yaml"); }

using arview::testing::LookingAtFox;

calib::Camera TestCamera() { return calib::Camera::Pinhole(640, 480, 600, 590, 322.5, 236.0); }

const cv::Scalar kMagenta(255, 0, 255);

cv::Mat NotBackground(const cv::Mat& image, const cv::Scalar& background) {
  cv::Mat diff, grey, mask;
  cv::absdiff(image, background, diff);
  cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, mask, 40, 255, cv::THRESH_BINARY);
  return mask;
}

// The silhouette of anim/'s CPU-skinned meshes, projected with OpenCV and filled per triangle.
cv::Mat CpuSilhouette(const anim::Character& character, const authoring::CharacterSpec& spec,
                      const anim::AnimatorFrame& frame, anim::SkinningMethod method, const calib::Camera& camera,
                      const calib::Pose& pose) {
  cv::Mat mask = cv::Mat::zeros(camera.height, camera.width, CV_8U);
  const Eigen::Matrix4d model_to_map = spec.placement().ModelToMap();
  constexpr int kShift = 8;
  for (const anim::Mesh& mesh : character.meshes) {
    std::vector<Eigen::Vector3f> skinned(mesh.positions.size());
    anim::SkinningJob job{&mesh, method, frame.skinning_matrices, frame.skinning_dual_quats, skinned, {}};
    EXPECT_TRUE(job.Run());
    std::vector<cv::Point> pixels(skinned.size());
    for (size_t i = 0; i < skinned.size(); ++i) {
      const Eigen::Vector3d world = (model_to_map * skinned[i].cast<double>().homogeneous()).head<3>();
      const Eigen::Vector2d px = camera.Project(pose.ToCamera(world));
      pixels[i] = cv::Point(cvRound(px.x() * (1 << kShift)), cvRound(px.y() * (1 << kShift)));
    }
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      const cv::Point tri[3] = {pixels[mesh.indices[t]], pixels[mesh.indices[t + 1]], pixels[mesh.indices[t + 2]]};
      cv::fillConvexPoly(mask, tri, 3, cv::Scalar(255), cv::LINE_8, kShift);
    }
  }
  return mask;
}

double Iou(const cv::Mat& a, const cv::Mat& b) {
  const double uni = cv::countNonZero(a | b);
  return uni > 0 ? cv::countNonZero(a & b) / uni : 0.0;
}

// Options for silhouettes: no shadow, a background colour no character has.
ArOptions SilhouetteOptions(anim::SkinningMethod method) {
  ArOptions options;
  options.skinning = method;
  options.shadow = false;
  options.empty_background = kMagenta;
  return options;
}

struct Silhouettes {
  cv::Mat rendered, expected;  // GPU-skinned render, CPU-skinned reference
  double iou = 0;
};

Silhouettes Compare(ArRenderer& renderer, const authoring::AnimatedCharacter& c, const anim::AnimatorFrame* frame,
                    anim::SkinningMethod method, const calib::Camera& camera, const calib::Pose& pose) {
  Silhouettes s;
  s.rendered = NotBackground(renderer.Render({}, pose, {&frame, 1}), kMagenta);
  s.expected = CpuSilhouette(c.character(), c.spec(), *frame, method, camera, pose);
  s.iou = Iou(s.rendered, s.expected);
  return s;
}

class FoxTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
    scene_ = FoxScene();
    fox_ = std::make_unique<authoring::AnimatedCharacter>(scene_.characters[0]);
  }
  const anim::AnimatorFrame& Frame(double time, const calib::Pose& pose) {
    return fox_->Update(fox_->spec().placement().ViewpointFromCamera(pose.Center()), time);
  }
  authoring::Scene scene_;
  std::unique_ptr<authoring::AnimatedCharacter> fox_;
};

TEST_F(FoxTest, GpuSkinningMatchesCpuSkinningForBothMethods) {
  const calib::Camera camera = TestCamera();
  const calib::Pose pose = LookingAtFox();
  for (auto method : {anim::SkinningMethod::kDualQuaternion, anim::SkinningMethod::kLinear}) {
    ArRenderer renderer(testing::SharedContext(), camera, SilhouetteOptions(method));
    renderer.AddCharacter(fox_->character(), fox_->spec().placement());
    for (double time : {0.0, 0.37, 0.71}) {
      const Silhouettes s = Compare(renderer, *fox_, &Frame(time, pose), method, camera, pose);
      const cv::Mat& expected = s.expected;
      const double iou = s.iou;
      ASSERT_GT(cv::countNonZero(expected), 3000) << "the fox should fill part of the view";
      EXPECT_FALSE(renderer.used_linear_fallback());
      std::printf("%s t=%.2f: silhouette IoU %.4f (%d px)\n",
                  method == anim::SkinningMethod::kLinear ? "LBS" : "DQS", time, iou, cv::countNonZero(expected));
      EXPECT_GE(iou, 0.97);
    }
  }
}

// A first run moves its figure once it is seen (ArRenderer::MoveCharacter): drawn as a renderer
// given the new placement from the start draws it, not where it was.
TEST_F(FoxTest, AMovedCharacterIsDrawnWhereItWasMovedTo) {
  const calib::Camera camera = TestCamera();
  const calib::Pose pose = LookingAtFox();
  const anim::Placement before = fox_->spec().placement();
  anim::Placement after = before;
  after.anchor.rotation = before.anchor.rotation * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY());
  const anim::AnimatorFrame* frame = &Frame(0.2, pose);
  ArRenderer moved(testing::SharedContext(), camera, SilhouetteOptions(anim::SkinningMethod::kDualQuaternion));
  moved.AddCharacter(fox_->character(), before);
  const cv::Mat where_it_was = NotBackground(moved.Render({}, pose, {&frame, 1}), kMagenta);
  moved.MoveCharacter(0, after);
  const cv::Mat where_it_is = NotBackground(moved.Render({}, pose, {&frame, 1}), kMagenta);
  ArRenderer placed(testing::SharedContext(), camera, SilhouetteOptions(anim::SkinningMethod::kDualQuaternion));
  placed.AddCharacter(fox_->character(), after);
  const cv::Mat expected = NotBackground(placed.Render({}, pose, {&frame, 1}), kMagenta);
  ASSERT_GT(cv::countNonZero(expected), 1000) << "the fox should be in view";
  EXPECT_EQ(cv::countNonZero(where_it_is != expected), 0);
  EXPECT_LT(Iou(where_it_was, expected), 0.9) << "turned a quarter, its silhouette differs";
  EXPECT_THROW(moved.MoveCharacter(1, after), RenderError);
}

TEST_F(FoxTest, CompositesOverTheBackgroundWithAShadowBelow) {
  const calib::Camera camera = TestCamera();
  const calib::Pose pose = LookingAtFox();
  cv::Mat background(camera.height, camera.width, CV_8UC3);
  cv::randu(background, cv::Scalar::all(0), cv::Scalar::all(255));
  ArRenderer renderer(testing::SharedContext(), camera, {});
  renderer.AddCharacter(fox_->character(), fox_->spec().placement());
  const anim::AnimatorFrame* frame = &Frame(0.2, pose);
  const cv::Mat out = renderer.Render(background, pose, {&frame, 1});
  ASSERT_EQ(out.size(), background.size());

  ArOptions bare;
  bare.shadow = false;
  bare.empty_background = kMagenta;
  ArRenderer silhouette_renderer(testing::SharedContext(), camera, bare);
  silhouette_renderer.AddCharacter(fox_->character(), fox_->spec().placement());
  const cv::Mat fox = NotBackground(silhouette_renderer.Render({}, pose, {&frame, 1}), kMagenta);

  // Far from the character and its shadow, the video pixels are untouched.
  cv::Mat near, diff, changed;
  cv::dilate(fox, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, {121, 121}));
  cv::absdiff(out, background, diff);
  cv::cvtColor(diff, changed, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::countNonZero(changed & ~near), 0);
  // The character covers the video.
  EXPECT_GT(cv::mean(changed, fox)[0], 30);
  // Outside the character, the shadow only darkens, and does so over a visible area.
  cv::Mat out_grey, bg_grey, darker, brighter;
  cv::cvtColor(out, out_grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(background, bg_grey, cv::COLOR_BGR2GRAY);
  cv::subtract(bg_grey, out_grey, darker);
  cv::subtract(out_grey, bg_grey, brighter);
  const cv::Mat outside = ~fox;
  const int shadow_pixels = cv::countNonZero((darker > 10) & outside);
  std::printf("shadow darkens %d pixels by more than 10 grey levels\n", shadow_pixels);
  EXPECT_GT(shadow_pixels, 1500);
  cv::Mat away_from_rim;  // the antialiased rim of the character may be either
  cv::erode(outside, away_from_rim, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
  EXPECT_EQ(cv::countNonZero((brighter > 1) & away_from_rim), 0);
}

TEST_F(FoxTest, SideBySideEyesSeeTheCharacterWithDisparity) {
  const calib::Camera camera = TestCamera();
  const calib::Pose pose = LookingAtFox();
  ArRenderer renderer(testing::SharedContext(), camera, SilhouetteOptions(anim::SkinningMethod::kDualQuaternion));
  renderer.AddCharacter(fox_->character(), fox_->spec().placement());
  const anim::AnimatorFrame* frame = &Frame(0.0, pose);
  const cv::Mat both = renderer.RenderSideBySide({}, pose, {&frame, 1}, 0.064);
  ASSERT_EQ(both.size(), cv::Size(2 * camera.width, camera.height));
  const cv::Moments left = cv::moments(NotBackground(both(cv::Rect(0, 0, camera.width, camera.height)), kMagenta), true);
  const cv::Moments right =
      cv::moments(NotBackground(both(cv::Rect(camera.width, 0, camera.width, camera.height)), kMagenta), true);
  ASSERT_GT(left.m00, 1000);
  ASSERT_GT(right.m00, 1000);
  // An object in front: further right in the left eye, by about f·ipd/depth (~17 px at 2.2 m).
  const double disparity = left.m10 / left.m00 - right.m10 / right.m00;
  std::printf("disparity %.1f px\n", disparity);
  EXPECT_GT(disparity, 10);
  EXPECT_LT(disparity, 30);
  EXPECT_THROW(renderer.RenderSideBySide({}, pose, {&frame, 1}, -0.1), RenderError);
}

TEST_F(FoxTest, RejectsMismatchedInputs) {
  const calib::Camera camera = TestCamera();
  const calib::Pose pose = LookingAtFox();
  ArRenderer renderer(testing::SharedContext(), camera, {});
  renderer.AddCharacter(fox_->character(), fox_->spec().placement());
  const anim::AnimatorFrame* frame = &Frame(0.0, pose);
  EXPECT_THROW(renderer.Render(cv::Mat(100, 100, CV_8UC3), pose, {&frame, 1}), RenderError);
  EXPECT_THROW(renderer.Render({}, pose, {}), RenderError);
}

}  // namespace
}  // namespace arview::render

namespace arview::render {
namespace {

// Drawing only the bounded screen rectangle must give the same frame as drawing everything,
// including when the character is partly out of view or close.
TEST_F(FoxTest, BoundedRenderEqualsFullFrameRender) {
  const calib::Camera camera = TestCamera();
  cv::Mat background(camera.height, camera.width, CV_8UC3);
  cv::randu(background, cv::Scalar::all(0), cv::Scalar::all(255));
  ArOptions bounded_options, full_options;
  full_options.full_frame = true;
  ArRenderer bounded(testing::SharedContext(), camera, bounded_options);
  ArRenderer full(testing::SharedContext(), camera, full_options);
  bounded.AddCharacter(fox_->character(), fox_->spec().placement());
  full.AddCharacter(fox_->character(), fox_->spec().placement());
  const calib::Pose base = LookingAtFox();
  for (const Eigen::Vector3d& shift : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.6, 0, 1.2), Eigen::Vector3d(-0.3, 0.2, 1.6)}) {
    calib::Pose pose = base;
    pose.t_cw -= shift;  // moves the camera along its own axes: closer, off to one side
    for (double time : {0.1, 0.6}) {
      const anim::AnimatorFrame* frame = &Frame(time, pose);
      const cv::Mat a = bounded.Render(background, pose, {&frame, 1});
      const cv::Mat b = full.Render(background, pose, {&frame, 1});
      cv::Mat diff;
      cv::absdiff(a, b, diff);
      double worst = 0;
      cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
      EXPECT_LE(worst, 1) << "camera shift " << shift.transpose() << ", t = " << time;
    }
  }
}

// With lens distortion the video is undistorted to the pinhole view the characters are drawn
// in: a point's distorted image lands where the pinhole camera projects it.
TEST(ArRenderer, UndistortsTheBackgroundOntoThePinholeView) {
  calib::Camera camera = calib::Camera::Pinhole(640, 480, 520, 520, 318.0, 243.0);
  camera.dist = {-0.28, 0.08, 0.0012, -0.0007, 0};
  const calib::Camera pinhole = camera.WithoutDistortion();
  std::vector<Eigen::Vector3d> points;
  for (double x : {-0.45, 0.0, 0.45})
    for (double y : {-0.3, 0.0, 0.3}) points.emplace_back(x, y, 1.0);
  cv::Mat background = cv::Mat::zeros(camera.height, camera.width, CV_8UC3);
  constexpr int kShift = 8;
  for (const auto& p : points) {
    const Eigen::Vector2d d = camera.Project(p);
    cv::circle(background, cv::Point(cvRound(d.x() * (1 << kShift)), cvRound(d.y() * (1 << kShift))), 4 << kShift,
               cv::Scalar::all(255), cv::FILLED, cv::LINE_AA, kShift);
  }
  ArRenderer renderer(testing::SharedContext(), camera, {});
  const cv::Mat out = renderer.Render(background, calib::Pose{}, {});
  cv::Mat grey;
  cv::cvtColor(out, grey, cv::COLOR_BGR2GRAY);
  double worst = 0;
  for (const auto& p : points) {
    const Eigen::Vector2d expected = pinhole.Project(p);
    const cv::Rect window(cvRound(expected.x()) - 10, cvRound(expected.y()) - 10, 21, 21);
    const cv::Moments m = cv::moments(grey(window));
    ASSERT_GT(m.m00, 0);
    worst = std::max(worst, std::hypot(window.x + m.m10 / m.m00 - expected.x(), window.y + m.m01 / m.m00 - expected.y()));
  }
  std::printf("undistorted background: worst marker error %.3f px\n", worst);
  EXPECT_LT(worst, 0.3);
}

// A mesh without a texture is drawn by the program without the texture fetch (its material's
// colour alone), a textured one by the program with it, in the same draw: a red untextured
// quad beside a white one with a green texture.
TEST(ArRenderer, DrawsUntexturedMeshesInTheirColourAndTexturedOnesWithTheirTexture) {
  auto c = std::make_shared<anim::Character>();
  c->source = "two quads";
  c->skeleton.names = {"root"};
  c->skeleton.parents = {-1};
  c->skeleton.rest = {anim::Transform{}};
  c->skeleton.inverse_bind = {Eigen::Matrix4d::Identity()};
  for (const float x0 : {-0.6f, 0.1f}) {  // model space: y up, facing +z
    anim::Mesh quad;
    quad.name = x0 < 0 ? "red" : "green";
    const float x1 = x0 + 0.5f;
    quad.positions = {{x0, 0.7f, 0}, {x1, 0.7f, 0}, {x1, 1.3f, 0}, {x0, 1.3f, 0}};
    quad.normals.assign(4, Eigen::Vector3f::UnitZ());
    quad.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    quad.joints.assign(4, {0, 0, 0, 0});
    quad.weights.assign(4, Eigen::Vector4f(1, 0, 0, 0));
    quad.indices = {0, 1, 2, 0, 2, 3};
    quad.material = x0 < 0 ? 0 : 1;
    c->meshes.push_back(quad);
  }
  c->materials.push_back({"red", Eigen::Vector4f(0.9f, 0.1f, 0.1f, 1), -1});
  c->materials.push_back({"textured", Eigen::Vector4f::Ones(), 0});
  anim::Texture green;
  green.width = green.height = 2;
  for (int i = 0; i < 4; ++i) green.rgba.insert(green.rgba.end(), {0, 230, 0, 255});
  c->textures.push_back(green);
  authoring::CharacterSpec spec;
  spec.name = "quads";
  spec.anchor.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX());  // model y up → map z up
  authoring::KeySpec key;
  key.source = authoring::KeySpec::Source::kRestPose;
  spec.keys.push_back(key);
  authoring::AnimatedCharacter quads(std::shared_ptr<const anim::Character>(c), spec);

  const calib::Camera camera = TestCamera();
  const Eigen::Quaterniond level(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  const calib::Pose front = calib::Pose::FromCameraToWorld(level, Eigen::Vector3d(0, -2.2, 1.0));
  ArOptions options = SilhouetteOptions(anim::SkinningMethod::kDualQuaternion);
  options.cull_back_faces = false;
  ArRenderer renderer(testing::SharedContext(), camera, options);
  renderer.AddCharacter(quads.character(), quads.spec().placement());
  const anim::AnimatorFrame* frame = &quads.Update(front.Center(), 0.0);
  const cv::Mat out = renderer.Render({}, front, {&frame, 1});
  for (const double x : {-0.35, 0.35}) {
    const Eigen::Vector2d px = camera.Project(front.ToCamera(Eigen::Vector3d(x, 0, 1.0)));
    const cv::Scalar bgr = cv::mean(out(cv::Rect(cvRound(px.x()) - 5, cvRound(px.y()) - 5, 11, 11)));
    if (x < 0) {
      EXPECT_GT(bgr[2], 60) << "the red quad: " << bgr;
      EXPECT_GT(bgr[2], 3 * bgr[1]) << "the red quad: " << bgr;
      EXPECT_GT(bgr[2], 3 * bgr[0]) << "the red quad: " << bgr;
    } else {
      EXPECT_GT(bgr[1], 60) << "the green-textured quad: " << bgr;
      EXPECT_GT(bgr[1], 3 * bgr[2] + 1) << "the green-textured quad: " << bgr;
      EXPECT_GT(bgr[1], 3 * bgr[0] + 1) << "the green-textured quad: " << bgr;
    }
  }
}

}  // namespace
}  // namespace arview::render

namespace arview::render {
namespace {

// Back faces are culled: a closed, consistently wound mesh must lose nothing by it. CesiumMan
// (textured, 4 672 triangles) against anim/'s CPU skinning of all its triangles.
TEST(CesiumMan, GpuSilhouetteMatchesCpuSkinningWithBackFacesCulled) {
  const fs::path asset = arview::testing::SharedData("characters/CesiumMan.glb");
  ARVIEW_REQUIRE_DATA_PATH(asset, "../shared/data");
  const authoring::Scene scene = authoring::ParseScene(
      "characters:\n  - name: man\n    asset: " + asset.string() +
          "\n    anchor:\n      position: [0.1, 0, 0.2]\n      rotation_deg: [90, 0, 0]\n    keys:\n"
          "      - viewpoint: [0, 0, 1]\n        clip: Anim_0\n",
      "cesium_test.yaml");
  authoring::AnimatedCharacter man(scene.characters[0]);
  const calib::Camera camera = TestCamera();
  // 2.2 m in front and behind, at hip height, looking level.
  const Eigen::Quaterniond level(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  const calib::Pose front = calib::Pose::FromCameraToWorld(level, Eigen::Vector3d(0, -2.2, 1.0));
  const calib::Pose back = calib::Pose::FromCameraToWorld(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()) * level,
                                                          Eigen::Vector3d(0, 2.2, 1.0));
  for (auto method : {anim::SkinningMethod::kDualQuaternion, anim::SkinningMethod::kLinear}) {
    const ArOptions options = SilhouetteOptions(method);
    ArRenderer renderer(testing::SharedContext(), camera, options);
    renderer.AddCharacter(man.character(), man.spec().placement());
    for (const auto& [pose, time] : {std::pair{front, 0.0}, std::pair{back, 0.9}}) {
      const anim::AnimatorFrame* frame = &man.Update(man.spec().placement().ViewpointFromCamera(pose.Center()), time);
      const Silhouettes s = Compare(renderer, man, frame, method, camera, pose);
      const cv::Mat& expected = s.expected;
      const double iou = s.iou;
      ASSERT_GT(cv::countNonZero(expected), 2500);
      std::printf("CesiumMan %s t=%.1f: silhouette IoU %.4f (%d px)\n",
                  method == anim::SkinningMethod::kLinear ? "LBS" : "DQS", time, iou, cv::countNonZero(expected));
      EXPECT_GE(iou, 0.97);

      // Culling must only drop hidden triangles: the same frame drawn with every triangle.
      ArOptions all_faces = options;
      all_faces.cull_back_faces = false;
      ArRenderer reference(testing::SharedContext(), camera, all_faces);
      reference.AddCharacter(man.character(), man.spec().placement());
      cv::Mat diff, grey;
      cv::absdiff(renderer.Render({}, pose, {&frame, 1}), reference.Render({}, pose, {&frame, 1}), diff);
      cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
      EXPECT_LT(cv::countNonZero(grey > 8), 0.005 * cv::countNonZero(expected));
    }
  }
}

}  // namespace
}  // namespace arview::render

namespace arview::render {
namespace {

double WorstDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  double worst = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
  return worst;
}

// The Fox over a random background at two poses and times, 4x MSAA, through `context`.
std::vector<cv::Mat> FoxFrames(OffscreenContext& context, authoring::AnimatedCharacter& fox, const ArOptions& options) {
  context.MakeCurrent();
  const calib::Camera camera = TestCamera();
  cv::Mat background(camera.height, camera.width, CV_8UC3);
  cv::RNG(7).fill(background, cv::RNG::UNIFORM, 0, 256);  // the same for every call
  ArRenderer renderer(context, camera, options);
  renderer.AddCharacter(fox.character(), fox.spec().placement());
  std::vector<cv::Mat> frames;
  for (const Eigen::Vector3d& shift : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.6, 0, 1.2)}) {
    calib::Pose pose = LookingAtFox();
    pose.t_cw -= shift;
    for (double time : {0.1, 0.6}) {
      const anim::AnimatorFrame* frame = &fox.Update(fox.spec().placement().ViewpointFromCamera(pose.Center()), time);
      frames.push_back(renderer.Render(background, pose, {&frame, 1}));
    }
  }
  return frames;
}

// The EGL device platform is the way to a GPU; on this machine it reaches Mesa's software
// device, which must draw what OSMesa draws (the same llvmpipe).
TEST_F(FoxTest, EglDevicePlatformDrawsTheSameFramesAsOsMesa) {
  std::unique_ptr<OffscreenContext> osmesa, device;
  try {
    osmesa = OffscreenContext::Create(testing::GlOptions(GlBackend::kOsMesa, 2));
    device = OffscreenContext::Create(testing::GlOptions(GlBackend::kEglDevice, 2));
  } catch (const RenderError& e) {
    GTEST_SKIP() << "OSMesa or the EGL device platform is missing here: " << e.what();
  }
  std::printf("%s\n%s\n", osmesa->Description().c_str(), device->Description().c_str());
  const std::vector<cv::Mat> a = FoxFrames(*osmesa, *fox_, {});
  const std::vector<cv::Mat> b = FoxFrames(*device, *fox_, {});
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    const double worst = WorstDifference(a[i], b[i]);
    std::printf("frame %zu: largest difference %.0f\n", i, worst);
    EXPECT_LE(worst, 1) << "frame " << i;
  }
  testing::SharedContext();  // current again for the tests that follow
}

// A GPU reads the layer back through a pixel buffer; the pixels are the same as glReadPixels'.
TEST_F(FoxTest, PixelBufferReadbackGivesTheSameFramesAsADirectRead) {
  ArOptions direct, pixel_buffer;
  direct.readback = Readback::kDirect;
  pixel_buffer.readback = Readback::kPixelBuffer;
  const std::vector<cv::Mat> a = FoxFrames(testing::SharedContext(), *fox_, direct);
  const std::vector<cv::Mat> b = FoxFrames(testing::SharedContext(), *fox_, pixel_buffer);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(WorstDifference(a[i], b[i]), 0) << "frame " << i;
  EXPECT_FALSE(ArRenderer(testing::SharedContext(), TestCamera(), {}).reads_through_pixel_buffer())
      << "llvmpipe keeps the direct read (its raster overlaps the cast shadow's darkening)";
}

}  // namespace
}  // namespace arview::render
