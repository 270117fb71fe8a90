#include "recordings/accuracy.h"

#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

namespace arview::recordings {
namespace {

namespace fs = std::filesystem;

Sim3 RandomSim3(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0, 1);
  Sim3 s;
  s.R = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
  s.t = Eigen::Vector3d(n(rng), n(rng), n(rng)) * 3;
  s.scale = scale;
  return s;
}

// A camera orbiting a point, looking at it, with some height variation: 3D, not degenerate.
Trajectory Orbit(int n, double t0 = 0, double dt = 1) {
  Trajectory out;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const Eigen::Vector3d C(std::cos(a), std::sin(a), 0.2 * std::sin(3 * a));
    const Eigen::Vector3d z = (-C).normalized();
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
    Eigen::Matrix3d R_wc;
    R_wc << x, z.cross(x), z;
    out.push_back({t0 + i * dt, calib::Pose::FromCameraToWorld(Eigen::Quaterniond(R_wc), C)});
  }
  return out;
}

TEST(Umeyama, RecoversAKnownSimilarityExactly) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  const Sim3 truth = RandomSim3(rng, 2.5);
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 20; ++i) {
    src.emplace_back(n(rng), n(rng), n(rng));
    dst.push_back(truth(src.back()));
  }
  const Sim3 s = Umeyama(src, dst, true);
  EXPECT_NEAR(s.scale, 2.5, 1e-12);
  EXPECT_LT((s.R - truth.R).norm(), 1e-12);
  EXPECT_LT((s.t - truth.t).norm(), 1e-12);
  // Rigid: the same with scale 1.
  Sim3 rigid = truth;
  rigid.scale = 1;
  for (size_t i = 0; i < src.size(); ++i) dst[i] = rigid(src[i]);
  const Sim3 r = Umeyama(src, dst, false);
  EXPECT_DOUBLE_EQ(r.scale, 1.0);
  EXPECT_LT((r.R - rigid.R).norm(), 1e-12);
  EXPECT_LT((r.t - rigid.t).norm(), 1e-12);
  // A reflection in the data is not returned as a rotation.
  EXPECT_NEAR(s.R.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, RejectsDegeneratePointSets) {
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(Umeyama(two, two, true), RecordingError);
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {5, 0, 0}};
  EXPECT_THROW(Umeyama(line, line, true), RecordingError);
  const std::vector<Eigen::Vector3d> plane = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_NO_THROW(Umeyama(plane, plane, true));
}

TEST(Sim3, InverseAndApplyAgree) {
  std::mt19937 rng(3);
  const Sim3 s = RandomSim3(rng, 0.3);
  const calib::Pose p = Orbit(10)[3].pose;
  const calib::Pose back = Transform(s.Inverse(), Transform(s, p));
  EXPECT_LT((back.Center() - p.Center()).norm(), 1e-12);
  EXPECT_LT(RotationErrorDeg(back, p), 1e-6);
  EXPECT_LT((s.Matrix() * s.Inverse().Matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-12);
}

TEST(EvaluateTrajectory, SelfUnderRandomSim3HasZeroErrorOnlyAfterSim3Alignment) {
  std::mt19937 rng(11);
  const Trajectory gt = Orbit(60);
  const Sim3 moved = RandomSim3(rng, 0.37);
  const Trajectory est = TransformTrajectory(gt, moved);

  AccuracyOptions sim3;
  const AccuracyReport r = EvaluateTrajectory(est, gt, sim3);
  EXPECT_LT(r.ate.rmse, 1e-9);
  EXPECT_LT(r.ate.max, 1e-9);
  EXPECT_LT(r.rotation_deg.max, 1e-5);
  EXPECT_LT(r.rpe_translation.max, 1e-9);
  EXPECT_NEAR(r.alignment.scale, 1 / 0.37, 1e-9);
  EXPECT_EQ(r.associated, 60);
  EXPECT_DOUBLE_EQ(r.coverage, 1.0);

  AccuracyOptions none;
  none.align = AlignMode::kNone;
  const AccuracyReport n = EvaluateTrajectory(est, gt, none);
  EXPECT_GT(n.ate.rmse, 0.1);
  EXPECT_GT(n.rotation_deg.median, 1.0);

  AccuracyOptions se3;
  se3.align = AlignMode::kSE3;
  const AccuracyReport s = EvaluateTrajectory(est, gt, se3);
  EXPECT_GT(s.ate.rmse, 0.1);              // the scale is wrong
  EXPECT_LT(s.rotation_deg.max, 1e-5);     // but the orientations are recovered
  EXPECT_DOUBLE_EQ(s.alignment.scale, 1.0);
}

TEST(EvaluateTrajectory, AlignWithFitsOnTheOtherTrajectoryOnly) {
  std::mt19937 rng(5);
  const Trajectory gt = Orbit(40);
  const Sim3 moved = RandomSim3(rng, 2.0);
  // "Keyframes": the even frames, exact. "Queries": the odd frames, each pushed 0.1 off in the
  // ground-truth world (0.05 in the estimate world, whose scale is 2).
  Trajectory keyframes, queries;
  for (size_t i = 0; i < gt.size(); ++i) {
    if (i % 2 == 0) {
      keyframes.push_back({gt[i].timestamp, Transform(moved, gt[i].pose)});
    } else {
      calib::Pose p = gt[i].pose;
      p = calib::Pose::FromCameraToWorld(p.CameraToWorldRotation(), p.Center() + Eigen::Vector3d(0.1, 0, 0));
      queries.push_back({gt[i].timestamp, Transform(moved, p)});
    }
  }
  AccuracyOptions opt;
  opt.align_with = &keyframes;
  const AccuracyReport r = EvaluateTrajectory(queries, gt, opt);
  EXPECT_TRUE(r.aligned_with_other);
  EXPECT_EQ(r.alignment_pairs, 20);
  EXPECT_EQ(r.associated, 20);
  EXPECT_NEAR(r.coverage, 0.5, 1e-12);
  EXPECT_NEAR(r.ate.median, 0.1, 1e-9);
  EXPECT_NEAR(r.ate.max, 0.1, 1e-9);
  // Fitting on the queries themselves absorbs the common offset: the dishonest protocol.
  const AccuracyReport self = EvaluateTrajectory(queries, gt, {});
  EXPECT_LT(self.ate.median, 0.01);
}

TEST(AssociateByTimestamp, PairsWithinToleranceOneToOne) {
  Trajectory a = Orbit(5, 0.0, 1.0);  // 0 1 2 3 4
  Trajectory b = Orbit(5, 0.005, 1.0);  // 0.005 1.005 ...
  b[2].timestamp = 2.5;                 // too far from 2
  std::swap(b[0], b[4]);                // order must not matter
  const auto pairs = AssociateByTimestamp(a, b, 0.01);
  ASSERT_EQ(pairs.size(), 4u);
  EXPECT_EQ(pairs[0], std::make_pair(size_t{0}, size_t{4}));
  EXPECT_EQ(pairs[1], std::make_pair(size_t{1}, size_t{1}));
  EXPECT_EQ(pairs[2], std::make_pair(size_t{3}, size_t{3}));
  EXPECT_EQ(pairs[3], std::make_pair(size_t{4}, size_t{0}));
  // Two candidates for one ground-truth pose: the closer one wins.
  Trajectory c = Orbit(2, 0.0, 0.004);  // 0, 0.004
  Trajectory d = Orbit(1, 0.003, 1.0);
  const auto one = AssociateByTimestamp(c, d, 0.01);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].first, 1u);
  EXPECT_TRUE(AssociateByTimestamp(a, b, 0.001).empty());
  EXPECT_THROW(AssociateByTimestamp(a, b, -1), RecordingError);
}

TEST(EvaluateTrajectory, RelativePoseErrorSeesOneDisplacedPose) {
  const Trajectory gt = Orbit(30);
  Trajectory est = gt;
  est[10].pose = calib::Pose::FromCameraToWorld(gt[10].pose.CameraToWorldRotation(),
                                                gt[10].pose.Center() + Eigen::Vector3d(0, 0, 0.05));
  AccuracyOptions opt;
  opt.align = AlignMode::kNone;
  const AccuracyReport r = EvaluateTrajectory(est, gt, opt);
  EXPECT_EQ(r.rpe_translation.count, 29u);
  EXPECT_NEAR(r.rpe_translation.max, 0.05, 1e-12);
  EXPECT_NEAR(r.rpe_translation.median, 0.0, 1e-12);
  EXPECT_NEAR(r.ate.max, 0.05, 1e-12);
  EXPECT_NEAR(r.ate.rmse, 0.05 / std::sqrt(30.0), 1e-12);
  opt.rpe_delta = 5;
  EXPECT_EQ(EvaluateTrajectory(est, gt, opt).rpe_translation.count, 25u);
}

TEST(EvaluateTrajectory, ReportsWhatItCannotJudge) {
  const Trajectory gt = Orbit(10);
  const Trajectory late = Orbit(10, 100.0);
  EXPECT_THROW(EvaluateTrajectory(late, gt), RecordingError);  // nothing to align on
  AccuracyOptions none;
  none.align = AlignMode::kNone;
  EXPECT_THROW(EvaluateTrajectory(late, gt, none), RecordingError);  // nothing associated
  EXPECT_THROW(EvaluateTrajectory({}, gt), RecordingError);
  EXPECT_THROW(ParseAlignMode("affine"), RecordingError);
  EXPECT_EQ(ParseAlignMode("se3"), AlignMode::kSE3);
}

TEST(ReportToJson, HoldsTheHeadlineNumbers) {
  const Trajectory gt = Orbit(12);
  const AccuracyReport r = EvaluateTrajectory(gt, gt);
  const std::string json = ReportToJson(r);
  for (const char* key : {"\"ate\"", "\"rmse\"", "\"median\"", "\"coverage\": 1", "\"align\": \"sim3\"",
                          "\"rpe_translation\"", "\"rotation_deg\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
  }
  EXPECT_NE(ReportToText(r).find("ATE"), std::string::npos);
}

// Issue 57: with too few associated poses for one RPE pair, the JSON said rmse 0.0 from zero
// pairs where the text said "not computed".
TEST(ReportToJson, AnRpeOfNoPairsIsNullWithTheReason) {
  const Trajectory gt = Orbit(12);
  AccuracyOptions options;
  options.rpe_delta = 20;  // more than the 12 associated poses
  const std::string json = ReportToJson(EvaluateTrajectory(gt, gt, options));
  EXPECT_NE(json.find("\"rpe_translation\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"rpe_rotation_deg\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"rpe_not_computed\": \"fewer than 21 associated poses\""), std::string::npos) << json;
  EXPECT_NE(ReportToText(EvaluateTrajectory(gt, gt, options)).find("not computed: fewer than 21 associated poses"),
            std::string::npos);
  EXPECT_EQ(ReportToJson(EvaluateTrajectory(gt, gt)).find("rpe_not_computed"), std::string::npos);
}

TEST(PlotTrajectories, DrawsBothViewsWithErrorColours) {
  const Trajectory gt = Orbit(50);
  Trajectory est = gt;
  for (size_t i = 0; i < est.size(); ++i) {
    est[i].pose = calib::Pose::FromCameraToWorld(est[i].pose.CameraToWorldRotation(),
                                                 est[i].pose.Center() + Eigen::Vector3d(0, 0, 0.002 * i));
  }
  AccuracyOptions opt;
  opt.align = AlignMode::kNone;
  const AccuracyReport r = EvaluateTrajectory(est, gt, opt);
  const fs::path png = fs::temp_directory_path() / ("arview_plot_" + std::to_string(::getpid()) + ".png");
  PlotTrajectories(r, gt, png, 800, 400);
  const cv::Mat image = cv::imread(png.string());
  fs::remove(png);
  ASSERT_EQ(image.size(), cv::Size(800, 400));
  // Both panels hold red-ish (large error) and blue-ish (small error) estimate marks.
  for (const cv::Rect half : {cv::Rect(0, 40, 400, 310), cv::Rect(400, 40, 400, 310)}) {
    int red = 0, blue = 0;
    const cv::Mat roi = image(half);
    for (int y = 0; y < roi.rows; ++y) {
      for (int x = 0; x < roi.cols; ++x) {
        const cv::Vec3b c = roi.at<cv::Vec3b>(y, x);
        red += c[2] > 200 && c[0] < 80 && c[1] < 80;
        blue += c[0] > 200 && c[2] < 80 && c[1] < 80;
      }
    }
    EXPECT_GT(red, 20);
    EXPECT_GT(blue, 20);
  }
  EXPECT_THROW(PlotTrajectories(r, gt, "/nonexistent-folder/plot.png"), arview::Error);
}

TEST(Tum, WriteThenReadRoundTrips) {
  const Trajectory gt = Orbit(7, 1.3e9, 0.033);
  const fs::path file = fs::temp_directory_path() / ("arview_tum_" + std::to_string(::getpid()) + ".txt");
  WriteTum(gt, file, "test");
  const Trajectory back = ReadTum(file);
  fs::remove(file);
  ASSERT_EQ(back.size(), gt.size());
  for (size_t i = 0; i < gt.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, gt[i].timestamp, 1e-6);
    EXPECT_LT((back[i].pose.Center() - gt[i].pose.Center()).norm(), 1e-12);
    EXPECT_LT(RotationErrorDeg(back[i].pose, gt[i].pose), 1e-6);
  }
}

std::string FileText(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A live session streams its poses (app/session): the file must be the one WriteTum would write,
// and only once finished.
TEST(TumFileWriter, WritesWhatWriteTumWritesAndOnlyOnceFinished) {
  const Trajectory gt = Orbit(9, 1.3e9, 0.033);
  const fs::path dir = fs::temp_directory_path() / ("arview_tumw_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  WriteTum(gt, dir / "whole.txt", "test");
  {
    TumFileWriter writer(dir / "streamed.txt", "test");
    for (const StampedPose& p : gt) writer.Add(p);
    EXPECT_EQ(writer.poses(), gt.size());
    EXPECT_FALSE(fs::exists(dir / "streamed.txt"));  // not before Finish
    writer.Finish();
  }
  EXPECT_EQ(FileText(dir / "streamed.txt"), FileText(dir / "whole.txt"));
  {
    TumFileWriter unfinished(dir / "cut.txt");
    unfinished.Add(gt.front());
  }
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find("cut"), std::string::npos) << entry.path();
  EXPECT_THROW(TumFileWriter(dir, "test"), arview::Error);  // a folder
  EXPECT_THROW(TumFileWriter(dir / "no-such-folder" / "t.txt"), arview::Error);
  fs::remove_all(dir);
}

TEST(Tum, MalformedLinesAreNamedWithFileAndLine) {
  const fs::path file = fs::temp_directory_path() / ("arview_tum_bad_" + std::to_string(::getpid()) + ".txt");
  auto error_for = [&](const std::string& text) {
    std::ofstream(file) << text;
    try {
      ReadTum(file);
    } catch (const RecordingError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_for("# c\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0\n").find(":3: expected"), std::string::npos);
  EXPECT_NE(error_for("1 0 0 0 0 0 0 1 7\n").find(":1: unexpected '7'"), std::string::npos);
  EXPECT_NE(error_for("1 0 0 0 0 0 0 2\n").find(":1: quaternion"), std::string::npos);
  EXPECT_NE(error_for("1 0 nan 0 0 0 0 1\n").find(":1:"), std::string::npos);
  EXPECT_EQ(error_for("\n# only comments\n1 0 0 0 0 0 0 1\n"), "");
  // Issue 41, found by fuzz_eval: a centre at 8.7e306 was read, and `eval --align none` printed
  // "ATE rmse inf" and an RPE of -nan, exit 0.
  EXPECT_NE(error_for("1 0 0 0 0 0 0 1\n1.2 0.0871e308 -0.99 0.6 0 0 0.564642 0.825336\n")
                .find(":2: the position (8.71e+306, -0.99, 0.6) lies beyond 1e+100 of the origin"),
            std::string::npos);
  EXPECT_EQ(error_for("1 1e99 0 0 0 0 0 1\n"), "");
  fs::remove(file);
}

// Issue 57: two different poses at one time were read, and the association dropped one unsaid.
TEST(Tum, TwoPosesAtOneTimeAreRefusedNamingBothLines) {
  const fs::path file = fs::temp_directory_path() / ("arview_tum_twice_" + std::to_string(::getpid()) + ".txt");
  std::ofstream(file) << "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n# again\n1 0.5 0 0 0 0 0 1\n";
  try {
    ReadTum(file);
    FAIL() << "two poses at 1 s read";
  } catch (const RecordingError& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ":4: a second pose at the time 1 s, another than line 1's: one "
                                                      "time, one pose");
  }
  std::ofstream(file) << "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n";  // the same pose again
  EXPECT_EQ(ReadTum(file).size(), 2u);
  fs::remove(file);
}

// Trajectories made in code are held to the same limit, and so is the estimate once aligned: a
// scale fitted on other poses must not carry it beyond what the errors' squares can hold.
TEST(EvaluateTrajectory, RefusesPositionsWhoseErrorsWouldOverflow) {
  const Trajectory gt = Orbit(20);
  Trajectory far = gt;
  far[7].pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 1e200, 0));
  for (const AlignMode mode : {AlignMode::kNone, AlignMode::kSE3, AlignMode::kSim3}) {
    AccuracyOptions o;
    o.align = mode;
    for (const bool far_estimate : {true, false}) {
      try {
        EvaluateTrajectory(far_estimate ? far : gt, far_estimate ? gt : far, o);
        ADD_FAILURE() << "scored a pose at 1e200";
      } catch (const RecordingError& e) {
        EXPECT_NE(std::string(e.what()).find(std::string("evaluation: the ") +
                                             (far_estimate ? "estimate" : "ground truth") + ": the pose at 7 s is at ("),
                  std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("1e+200"), std::string::npos) << e.what();
      }
    }
  }
  // Fitted on keyframes a thousand times smaller than the estimate, far poses of the estimate
  // (not among the keyframes) are carried beyond the limit.
  Trajectory keyframes, estimate = Orbit(20);
  for (const StampedPose& p : gt) {
    keyframes.push_back({p.timestamp, calib::Pose::FromCameraToWorld(p.pose.CameraToWorldRotation(), 1e-60 * p.pose.Center())});
  }
  estimate[5].pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond::Identity(), Eigen::Vector3d(9e99, 0, 0));
  keyframes.erase(keyframes.begin() + 5);
  AccuracyOptions o;
  o.align_with = &keyframes;
  try {
    EvaluateTrajectory(estimate, gt, o);
    ADD_FAILURE() << "scored an estimate carried to 1e160";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("evaluation: the estimate aligned with a scale of"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arview::recordings
