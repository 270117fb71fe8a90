// The map of templeRing's 24 even frames, built with COLMAP (about half a minute on two idle
// cores) and shared by every check: registration, reprojection error, accuracy against the
// Middlebury ground truth, the files written, re-use of finished stages, and how the readers
// handle truncated or corrupted copies of COLMAP's output.
//
// ctest runs each test in its own process, so the map lives in a fixed folder
// ($TMPDIR/arview_temple_map_test_<uid>) under a file lock: the first process builds it, every
// other one re-uses it through BuildMap's stage records (all three COLMAP stages skipped, the
// model still read and checked). Each process writes its scratch files in its own sub-folder.

#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <iostream>
#include <map>
#include <memory>

#include "map/descriptor_index.h"
#include "map/map_file.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/map_check.h"
#include "mapping/test_temple_map.h"
#include "recordings/accuracy.h"
#include "recordings/importers.h"
#include "recordings/trajectory.h"
#include "tests/support/test_data.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

class TempleMapTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path source = testing::SharedData("templeRing");
    if (!fs::exists(source)) return;  // each test skips (or fails under ARVIEW_REQUIRE_DATA=1)
    root_ = testing::TempleMapRoot();
    scratch_ = root_ / ("scratch_" + std::to_string(::getpid()));
    fs::create_directories(scratch_);
    recording_ = std::make_unique<recordings::Recording>();
    MapBuildCallbacks cb;
    cb.progress = [](const std::string& stage, int done, int total) { progress_[stage] = {done, total}; };
    result_ = std::make_unique<MapBuildResult>(testing::BuildSharedTempleMap(source, recording_.get(), cb));
  }
  static void TearDownTestSuite() {
    if (!scratch_.empty()) fs::remove_all(scratch_);
    result_.reset();
    recording_.reset();
  }
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("templeRing"), "../shared/data");
    ASSERT_TRUE(result_) << "building the map failed in SetUpTestSuite";
  }

  static const map::Map& map() { return result_->map; }
  static fs::path MapDir() { return root_ / "map"; }

  // A copy of the model folder (and database) with one file cut to `bytes` or overwritten.
  static fs::path BrokenCopy(const std::string& file, const std::function<void(std::vector<char>&)>& damage) {
    const fs::path dir = scratch_ / "broken";
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
      fs::copy_file(result_->model_dir / name, dir / name);
    }
    fs::copy_file(MapDir() / "database.db", dir / "database.db");
    std::vector<char> bytes;
    {
      std::ifstream in(dir / file, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    damage(bytes);
    std::ofstream out(dir / file, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return dir;
  }

  static fs::path root_;
  static std::unique_ptr<recordings::Recording> recording_;
  static std::unique_ptr<MapBuildResult> result_;
  static fs::path scratch_;
  static std::map<std::string, std::pair<int, int>> progress_;  // each stage's last progress
};
std::map<std::string, std::pair<int, int>> TempleMapTest::progress_;

fs::path TempleMapTest::root_;
std::unique_ptr<recordings::Recording> TempleMapTest::recording_;
std::unique_ptr<MapBuildResult> TempleMapTest::result_;
fs::path TempleMapTest::scratch_;

// Every stage that ran reported progress up to its end: COLMAP's stages through the parser of
// their output, arview's matching pair by pair, COLMAP's verification of its matches.
TEST_F(TempleMapTest, ProgressFollowsEveryStageToItsEnd) {
  // Where a stage's end is known: 24 frames, every pair of them, every frame registered.
  const std::map<std::string, std::pair<int, int>> ends{{"extract", {24, 24}}, {"match", {276, 276}}, {"map", {24, 24}}};
  for (const StageTiming& t : result_->timings) {
    if (t.skipped || t.stage == "write" || t.stage == "select") continue;  // skipped: the folder was in place
    ASSERT_TRUE(progress_.count(t.stage)) << t.stage << " ran without progress";
    const auto [done, total] = progress_[t.stage];
    EXPECT_GT(total, 0) << t.stage;
    EXPECT_EQ(done, total) << t.stage;
    if (ends.count(t.stage)) {
      EXPECT_EQ(progress_[t.stage], ends.at(t.stage)) << t.stage;
    }
  }
  EXPECT_EQ(ParseColmapProgress("Matching block [2/3, 1/3] in 1.2s", 0), std::make_pair(4, 9));
  EXPECT_EQ(ParseColmapProgress("Matching block [3/20] in 0.8s", 0), std::make_pair(3, 20));
  EXPECT_EQ(ParseColmapProgress("Matching image [5/40] in 0.5s", 0), std::make_pair(5, 40));
  EXPECT_EQ(ParseColmapProgress("Processed file [3/24]", 0), std::make_pair(3, 24));
  EXPECT_EQ(ParseColmapProgress("Registering image #4 (7)", 24), std::make_pair(7, 24));
  EXPECT_FALSE(ParseColmapProgress("Bundle adjustment report", 24).has_value());
}

TEST_F(TempleMapTest, RegistersAllTwentyFourEvenFrames) {
  ASSERT_EQ(result_->selected_frames.size(), 24u);
  ASSERT_EQ(map().keyframes.size(), 24u);
  for (size_t i = 0; i < map().keyframes.size(); ++i) {
    EXPECT_EQ(map().keyframes[i].frame_index, static_cast<int>(2 * i));
    EXPECT_EQ(map().keyframes[i].timestamp, recording_->frames[2 * i].timestamp);
    EXPECT_EQ(map().keyframes[i].name, recording_->frames[2 * i].path);
  }
  EXPECT_EQ(result_->models, 1);
}

TEST_F(TempleMapTest, CameraComesBackInOpenCvPixels) {
  // Fixed intrinsics: exactly the recording's, the +0.5 handed to COLMAP removed again.
  EXPECT_NEAR(map().camera.cx, recording_->camera.cx, 1e-9);
  EXPECT_NEAR(map().camera.cy, recording_->camera.cy, 1e-9);
  EXPECT_NEAR(map().camera.fx, recording_->camera.fx, 1e-9);
}

TEST_F(TempleMapTest, ReprojectionErrorBelowOnePixel) {
  const map::MapStats s = map::ComputeStats(map());
  EXPECT_GT(s.points, 1000u);
  EXPECT_GT(s.mean_track_length, 2.5);
  EXPECT_LE(s.mean_reprojection_error, 1.0);
  // Our reprojection (OpenCV convention both sides) agrees with COLMAP's own figure: a
  // half-pixel slip in either conversion would show here.
  EXPECT_NEAR(s.mean_reprojection_error, s.mean_colmap_point_error, 0.1);
}

TEST_F(TempleMapTest, KeyframeCentresMatchGroundTruthAfterSim3) {
  ASSERT_TRUE(recording_->groundtruth.has_value());
  const recordings::Trajectory keyframes = recordings::ReadTum(MapDir() / "keyframes.txt");
  ASSERT_EQ(keyframes.size(), 24u);
  const recordings::AccuracyReport report = recordings::EvaluateTrajectory(keyframes, *recording_->groundtruth);
  EXPECT_EQ(report.associated, 24);
  EXPECT_LE(report.ate.median, 0.002) << recordings::ReportToText(report);
  EXPECT_LE(report.rotation_deg.median, 0.5);
}

// The self-check (mapping/map_check.h) finds nothing wrong with a real, good map: a camera
// circling an object on a turntable-like ring (issue 17: "templeRing's map not flagged").
TEST_F(TempleMapTest, TheSelfCheckFlagsNothing) {
  const MapCheck& c = result_->check;
  std::cout << "[templeRing] " << DescribeMapCheck(c) << "\n";
  EXPECT_FALSE(c.flagged()) << (c.warnings.empty() ? "" : c.warnings[0]);
  EXPECT_EQ(c.keyframes, 24);
  EXPECT_GT(c.moving_pairs, 20);
  // The camera rotations against COLMAP's own two-view geometry of the well-matched pairs: read
  // from the database (the convention of its stored essential matrices is right, or every pair
  // would disagree) and agreeing (1 of 30 pairs disagreed on a default map; 28% on phone-fox's
  // folded one, 0-7% on its good ones).
  EXPECT_GT(c.two_view_pairs, 10);
  EXPECT_LT(c.disagreeing_fraction, 0.15);
  const auto saved = ReadMapCheck(MapDir() / kMapCheckFileName);
  ASSERT_TRUE(saved);
  EXPECT_FALSE(saved->flagged());
  EXPECT_EQ(saved->two_view_pairs, c.two_view_pairs);
}

// `arview map info --recheck` computes the same check again from the folder.
TEST_F(TempleMapTest, RecheckFromTheFolderGivesTheSameCheck) {
  const MapCheck again = RecheckMap(MapDir());
  const MapCheck& c = result_->check;
  EXPECT_EQ(again.keyframes, c.keyframes);
  EXPECT_DOUBLE_EQ(again.explained_fraction, c.explained_fraction);
  EXPECT_EQ(again.two_view_pairs, c.two_view_pairs);
  EXPECT_DOUBLE_EQ(again.disagreeing_fraction, c.disagreeing_fraction);
  EXPECT_EQ(again.warnings, c.warnings);
}

TEST_F(TempleMapTest, CompactFileLoadsTheSameMap) {
  const map::Map loaded = map::LoadMap(MapDir());
  ASSERT_EQ(loaded.keyframes.size(), map().keyframes.size());
  ASSERT_EQ(loaded.points.size(), map().points.size());
  EXPECT_EQ(loaded.descriptor_point, map().descriptor_point);
  EXPECT_EQ(cv::norm(loaded.descriptors, map().descriptors, cv::NORM_INF), 0);
  EXPECT_TRUE(fs::exists(MapDir() / "map.png"));
  EXPECT_TRUE(fs::exists(result_->model_dir / "points3D.bin"));
}

TEST_F(TempleMapTest, DescriptorsAreColmapUint8Sift) {
  // L1-root SIFT scaled by 512: each row's squared values sum to about 512² (clamping and
  // rounding make it a little less).
  ASSERT_EQ(map().descriptors.type(), CV_8UC1);
  for (int r = 0; r < map().descriptors.rows; r += 97) {
    cv::Mat row;
    map().descriptors.row(r).convertTo(row, CV_64F);
    EXPECT_NEAR(std::sqrt(row.dot(row)), 512, 40) << "row " << r;
  }
  // The descriptors of one point's track resemble each other far more than random rows.
  const map::DescriptorIndex index(map().descriptors);
  int same_point = 0, tried = 0;
  for (int r = 0; r < map().descriptors.rows; r += 13, ++tried) {
    const auto nn = index.Knn(map().descriptors.ptr<std::uint8_t>(r), 2);
    same_point += nn.size() == 2 && map().descriptor_point[nn[1].row] == map().descriptor_point[static_cast<size_t>(r)];
  }
  EXPECT_GT(same_point, tried / 2);
}

TEST_F(TempleMapTest, ReRunSkipsEveryColmapStage) {
  MapBuildOptions options;  // the fixture's command
  options.frames_spec = "0-46:2";
  options.match_engine = MatchEngine::kArview;
  std::vector<std::string> notes;
  MapBuildCallbacks callbacks;
  callbacks.note = [&](const std::string& n) { notes.push_back(n); };
  const MapBuildResult again = BuildMap(*recording_, MapDir(), options, callbacks);
  int skipped = 0;
  for (const auto& t : again.timings) skipped += t.skipped;
  EXPECT_EQ(skipped, 3);
  EXPECT_EQ(std::count_if(notes.begin(), notes.end(),
                          [](const std::string& n) { return n.find("skipped") != std::string::npos; }),
            3);
  EXPECT_EQ(again.map.points.size(), map().points.size());
}

TEST_F(TempleMapTest, MissingColmapIsAClearError) {
  MapBuildOptions options;
  options.frames_spec = "0-46:2";
  options.colmap = "arview-no-colmap-here";
  try {
    BuildMap(*recording_, scratch_ / "no_colmap", options);
    FAIL() << "expected MapError";
  } catch (const map::MapError& e) {
    EXPECT_NE(std::string(e.what()).find("COLMAP not found"), std::string::npos) << e.what();
  }
}

TEST_F(TempleMapTest, FailingStageCarriesTheLogTail) {
  const fs::path fake = scratch_ / "fake_colmap.sh";
  {
    std::ofstream out(fake);
    out << "#!/bin/sh\necho \"fake colmap running $1\"\necho 'E: something broke' >&2\nexit 2\n";
  }
  fs::permissions(fake, fs::perms::owner_all);
  MapBuildOptions options;
  options.frames_spec = "0-4";
  options.colmap = fake.string();
  try {
    BuildMap(*recording_, scratch_ / "failing", options);
    FAIL() << "expected ColmapStageError";
  } catch (const ColmapStageError& e) {
    EXPECT_EQ(e.stage, "extract");
    EXPECT_NE(std::string(e.what()).find("exited with code 2"), std::string::npos) << e.what();
    ASSERT_EQ(e.log_tail.size(), 2u);
    EXPECT_EQ(e.log_tail[1], "E: something broke");
  }
}

// A COLMAP that is the real one, except that its mapper's n-th run turns the first k images (by
// id) of the model it made by 30 degrees about their own x axis, centres kept, for the n-th entry
// k > 0 of `turned` (a fold, as COLMAP once made on phone-fox), and fails for k < 0. Every
// command line goes to <dir>/calls, one per line.
fs::path ColmapFoldingModels(const fs::path& dir, const std::vector<int>& turned) {
  fs::create_directories(dir);
  {
    std::ofstream list(dir / "turned.txt");
    for (int k : turned) list << k << "\n";
  }
  const std::string runs = (dir / "runs").string(), text = (dir / "text").string();
  const fs::path script = dir / "colmap.sh";
  std::ofstream out(script);
  // World-to-camera q, t -> turn * q, turn * t (turn: 30 degrees about x; cos 15, sin 15 degrees).
  out << "#!/bin/sh\n"
         "echo \"$*\" >> '" << (dir / "calls").string() << "'\n"
         "colmap \"$@\" || exit $?\n"
         "[ \"$1\" = mapper ] || exit 0\n"
         "n=$(cat '" << runs << "' 2>/dev/null || echo 0); n=$((n + 1)); echo $n > '" << runs << "'\n"
         "k=$(sed -n \"${n}p\" '" << (dir / "turned.txt").string() << "')\n"
         "[ -n \"$k\" ] && [ \"$k\" -lt 0 ] && { echo 'ERROR: failed to create sparse model' >&2; exit 1; }\n"
         "[ -n \"$k\" ] && [ \"$k\" -gt 0 ] || exit 0\n"
         "prev=; for a in \"$@\"; do [ \"$prev\" = --output_path ] && model=$a/0; prev=$a; done\n"
         "rm -rf '" << text << "' && mkdir -p '" << text << "'\n"
         "colmap model_converter --input_path \"$model\" --output_path '" << text << "' --output_type TXT || exit 1\n"
         "awk -v k=$k 'BEGIN { c = 0.96592582628906831; s = 0.25881904510252074; C = 0.86602540378443865; S = 0.5 }\n"
         "  /^#/ { print; next }\n"
         "  { pose = !pose }\n"
         "  pose && $1 <= k { printf \"%s %.17g %.17g %.17g %.17g %.17g %.17g %.17g\", $1, c*$2 - s*$3, c*$3 + s*$2,"
         " c*$4 - s*$5, c*$5 + s*$4, $6, C*$7 - S*$8, S*$7 + C*$8;"
         " for (i = 9; i <= NF; ++i) printf \" %s\", $i; print \"\"; next }\n"
         "  { print }' '" << text << "/images.txt' > '" << text << "/turned.txt' || exit 1\n"
         "mv '" << text << "/turned.txt' '" << text << "/images.txt'\n"
         "exec colmap model_converter --input_path '" << text << "' --output_path \"$model\" --output_type BIN\n";
  out.close();
  fs::permissions(script, fs::perms::owner_all);
  return script;
}

// `arview map`'s pipeline on 16 of templeRing's frames (under half the pairs of the fixture's 24
// to match) through ColmapFoldingModels(turned), with notes collected.
MapBuildResult BuildFolding(const recordings::Recording& recording, const fs::path& out, const std::vector<int>& turned,
                            int retries, bool keep_folded, std::vector<std::string>* notes) {
  MapBuildOptions options;
  options.frames_spec = "0-30:2";
  options.fold_retries = retries;
  options.keep_folded = keep_folded;
  // COLMAP left 3 of these 16 frames out (6-10) in a run of these tests: the gap retry
  // (mapping/gap_retry.h, its own tests) would be the wrapper's second mapper run; the fold
  // retries are tested alone.
  options.gap_retry_angle_deg = 0;
  options.colmap = ColmapFoldingModels(out.string() + "_colmap", turned).string();
  MapBuildCallbacks cb;
  cb.note = [notes](const std::string& n) { notes->push_back(n); };
  return BuildMap(recording, out, options, cb);
}

bool Said(const std::vector<std::string>& notes, const std::string& text) {
  return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(text) != std::string::npos; });
}

// The COLMAP command lines ColmapFoldingModels saw for `out`.
std::vector<std::string> ColmapCalls(const fs::path& out) {
  std::ifstream in(out.string() + "_colmap/calls");
  std::vector<std::string> calls;
  for (std::string line; std::getline(in, line);) calls.push_back(line);
  return calls;
}

int CountStarting(const std::vector<std::string>& calls, const std::string& command) {
  return static_cast<int>(
      std::count_if(calls.begin(), calls.end(), [&](const std::string& c) { return c.rfind(command, 0) == 0; }));
}

// A folded model is mapped again on the same matches, from a keyframe the check found right; the
// first model that is not folded is kept, and nothing of the tries is left in the folder.
TEST_F(TempleMapTest, AFoldedModelIsMappedAgainFromAnotherStartUntilItIsNotFolded) {
  std::vector<std::string> notes;
  const fs::path out = scratch_ / "repaired";
  const MapBuildResult repaired = BuildFolding(*recording_, out, {4, 0}, 2, false, &notes);
  EXPECT_EQ(repaired.fold_retries, 1);
  EXPECT_FALSE(Folded(repaired.check)) << DescribeMapCheck(repaired.check);
  EXPECT_TRUE(Said(notes, "looks folded")) << ::testing::PrintToString(notes);
  EXPECT_TRUE(Said(notes, "mapping again from frame")) << ::testing::PrintToString(notes);
  EXPECT_TRUE(Said(notes, "is not folded")) << ::testing::PrintToString(notes);
  const std::vector<std::string> calls = ColmapCalls(out);
  // The frames are matched once (COLMAP's matcher, or arview's with one matches_importer per
  // core) and the matches kept for the second try.
  const auto matching = [](const std::string& c) {
    return c.rfind("matches_importer", 0) == 0 || c.find("_matcher") != std::string::npos;
  };
  const auto first_mapper = std::find_if(calls.begin(), calls.end(), [](const std::string& c) { return c.rfind("mapper", 0) == 0; });
  EXPECT_GE(std::count_if(calls.begin(), first_mapper, matching), 1) << ::testing::PrintToString(calls);
  EXPECT_EQ(std::count_if(first_mapper, calls.end(), matching), 0) << ::testing::PrintToString(calls);
  ASSERT_EQ(CountStarting(calls, "mapper"), 2) << ::testing::PrintToString(calls);
  EXPECT_NE(calls.back().find("--Mapper.init_image_id1"), std::string::npos) << calls.back();
  EXPECT_FALSE(fs::exists(out / "fold-tries"));
  EXPECT_FALSE(Folded(*ReadMapCheck(out / kMapCheckFileName)));
  EXPECT_EQ(map::LoadMap(out).keyframes.size(), repaired.map.keyframes.size());
}

// Folded twice (2, then 8 frames turned), out of retries: the map is refused with one line, the
// check beside it says why, and no map file is written. The same command with --keep-folded then
// writes the least folded model (the first) without running COLMAP's stages again.
TEST_F(TempleMapTest, AMapStillFoldedIsRefusedUnlessKept) {
  std::vector<std::string> notes;
  const fs::path out = scratch_ / "refused";
  try {
    BuildFolding(*recording_, out, {2, 8}, 1, false, &notes);
    FAIL() << "a folded map was accepted";
  } catch (const map::MapError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the map is folded and was not written"), std::string::npos) << what;
    EXPECT_NE(what.find("--keep-folded"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_TRUE(Said({notes.back()}, "the least folded model is the first")) << notes.back();
  EXPECT_FALSE(fs::exists(out / map::kMapFileName));
  EXPECT_FALSE(fs::exists(out / "fold-tries"));
  const std::optional<MapCheck> check = ReadMapCheck(out / kMapCheckFileName);
  ASSERT_TRUE(check);
  EXPECT_TRUE(Folded(*check));

  notes.clear();
  fs::remove(out.string() + "_colmap/calls");
  const MapBuildResult kept = BuildFolding(*recording_, out, {}, 0, true, &notes);
  EXPECT_TRUE(Folded(kept.check));
  EXPECT_EQ(kept.check.disagreeing_frames, check->disagreeing_frames);
  EXPECT_TRUE(fs::exists(out / map::kMapFileName));
  EXPECT_EQ(CountStarting(ColmapCalls(out), "mapper"), 0);  // its own calls: every stage skipped
}

// Folded, then the mapper fails from the new start: the first model is put back, with its stages
// recorded (a re-run skips them, then tries again), and kept with --keep-folded.
TEST_F(TempleMapTest, AFailedTryPutsTheFoldedModelBack) {
  std::vector<std::string> notes;
  const fs::path out = scratch_ / "after_failure";
  const MapBuildResult after_failure = BuildFolding(*recording_, out, {4, -1}, 2, true, &notes);
  EXPECT_EQ(after_failure.fold_retries, 1);
  EXPECT_TRUE(Folded(after_failure.check));
  EXPECT_TRUE(Said(notes, "try 1 failed: COLMAP mapper")) << ::testing::PrintToString(notes);
  EXPECT_TRUE(Said({notes.back()}, "the first")) << notes.back();
  EXPECT_FALSE(fs::exists(out / "fold-tries"));
  EXPECT_TRUE(fs::exists(out / "stages" / "match.inputs"));
  EXPECT_TRUE(fs::exists(out / "stages" / "map.inputs"));
  EXPECT_EQ(map::LoadMap(out).keyframes.size(), after_failure.map.keyframes.size());
}

TEST_F(TempleMapTest, TruncatedModelFilesAreClearErrors) {
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const auto size = fs::file_size(result_->model_dir / file);
    for (double fraction : {0.0, 0.001, 0.1, 0.5, 0.9, 0.999}) {
      const auto keep = static_cast<size_t>(fraction * static_cast<double>(size));
      const fs::path dir = BrokenCopy(file, [&](std::vector<char>& b) { b.resize(std::min(b.size(), keep)); });
      try {
        ReadColmapMap(dir, dir / "database.db");
        ADD_FAILURE() << file << " cut to " << keep << " bytes was accepted";
      } catch (const map::MapError& e) {
        EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      }
    }
  }
}

TEST_F(TempleMapTest, CorruptedCountsAndIdsAreClearErrors) {
  // A huge image count: refused before any allocation.
  fs::path dir = BrokenCopy("images.bin", [](std::vector<char>& b) { b[6] = 0x7f; });
  EXPECT_THROW(ReadColmapMap(dir, dir / "database.db"), map::MapError);
  // A track element pointing to a 2D point that does not point back (first track's image id).
  dir = BrokenCopy("points3D.bin", [](std::vector<char>& b) { b[8 + 8 + 24 + 3 + 8 + 8] ^= 0x55; });
  EXPECT_THROW(ReadColmapMap(dir, dir / "database.db"), map::MapError);
  // The database cut short or missing.
  dir = BrokenCopy("database.db", [](std::vector<char>& b) { b.resize(b.size() / 3); });
  EXPECT_THROW(ReadColmapMap(dir, dir / "database.db"), map::MapError);
  dir = BrokenCopy("database.db", [](std::vector<char>& b) { std::fill(b.begin(), b.begin() + 100, 'x'); });
  EXPECT_THROW(ReadColmapMap(dir, dir / "database.db"), map::MapError);
  EXPECT_THROW(ReadColmapMap(dir, dir / "no_such.db"), map::MapError);
  // A model whose images are not the recording's frames.
  EXPECT_THROW(ReadColmapMap(result_->model_dir, MapDir() / "database.db", FrameLookup{{"other.png", {}}}), map::MapError);
}

}  // namespace
}  // namespace arview::mapping
