// Extraction and matching as Slurm jobs (mapping/job_stages.h): the chunks alone, then a third of
// templeRing's frames extracted and matched here and as jobs on the cluster of
// scripts/slurm-local.sh, the two databases and maps compared.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "mapping/colmap_model.h"
#include "mapping/job_stages.h"
#include "mapping/test_slurm.h"
#include "recordings/accuracy.h"
#include "recordings/importers.h"
#include "recordings/trajectory.h"
#include "tests/support/test_data.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

TEST(JobStages, ItemsAreDealtInOrderIntoRunsThatDifferByOneAtMost) {
  using Runs = std::vector<std::pair<int, int>>;
  EXPECT_EQ(SplitIntoRuns(10, 3), (Runs{{0, 4}, {4, 7}, {7, 10}}));
  EXPECT_EQ(SplitIntoRuns(2, 5), (Runs{{0, 1}, {1, 2}})) << "never an empty run";
  EXPECT_EQ(SplitIntoRuns(7, 1), (Runs{{0, 7}}));
}

// Every verified pair of a database by its images' names, with its inliers.
std::map<std::pair<std::string, std::string>, int> PairsByName(const fs::path& database) {
  const DatabaseMatchGraph graph = ReadMatchGraph(database);
  std::map<std::uint32_t, std::string> names(graph.images.begin(), graph.images.end());
  std::map<std::pair<std::string, std::string>, int> pairs;
  for (const VerifiedPair& p : graph.pairs) pairs[std::minmax(names[p.image_a], names[p.image_b])] = p.inliers;
  return pairs;
}

// 6 of templeRing's frames (6-11: the fast preset maps them whole; COLMAP's matcher, no metric
// frame): here, then as 3 extraction jobs and 3 matching jobs.
TEST(TempleStagesOnSlurm, ExtractionAndMatchingAsJobsGiveTheDatabaseAndMapOfTheLocalStages) {
  const fs::path source = testing::SharedData("templeRing");
  ARVIEW_REQUIRE_DATA_PATH(source, "../shared/data");
  ARVIEW_REQUIRE_SLURM();
  const fs::path scratch = fs::temp_directory_path() / ("arview_stages_on_slurm_" + std::to_string(::getpid()));
  fs::remove_all(scratch);
  recordings::ImportOptions io;
  io.overwrite = true;
  recordings::ImportMiddlebury(source, scratch / "recording", io);
  const recordings::Recording recording = recordings::LoadRecording(scratch / "recording");

  MapBuildOptions options;
  options.frames_spec = "6-11";
  options.UseFastPreset();
  options.match_engine = MatchEngine::kColmap;
  const MapBuildResult local = BuildMap(recording, scratch / "local", options);

  options.engine = MapEngine::kSlurm;
  options.slurm_chunk = 2;
  options.slurm.poll = std::chrono::milliseconds(300);
  // Each job takes seconds: one whose COLMAP hangs is ended and submitted again, rather than holding
  // the one-node cluster past the test's own time limit (and every later Slurm test with it).
  options.slurm.time_limit_minutes = 3;
  std::vector<std::string> notes;
  MapBuildCallbacks cb;
  cb.note = [&](const std::string& note) { notes.push_back(note); };
  const MapBuildResult jobs = BuildMap(recording, scratch / "jobs", options, cb);
  const auto noted = [&](const std::string& text) {
    return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(noted("extract jobs on Slurm: ")) << "progress of the extraction jobs";
  EXPECT_TRUE(noted("match jobs on Slurm: ")) << "progress of the matching jobs";
  EXPECT_FALSE(fs::exists(scratch / "jobs" / "jobs" / "extract")) << "the jobs' databases removed once merged";
  EXPECT_FALSE(fs::exists(scratch / "jobs" / "database.db.merging"));
  EXPECT_TRUE(QueuedJobs("arview-map-extract").empty());

  // The same images with the same features (their ids may differ: COLMAP's extraction numbers
  // the frames in the order its threads finish them).
  const auto names_of = [](const fs::path& database) {
    std::vector<std::string> names;
    for (const auto& [id, name] : ReadMatchGraph(database).images) names.push_back(name);
    std::sort(names.begin(), names.end());
    return names;
  };
  const std::vector<std::string> names = names_of(scratch / "local" / "database.db");
  ASSERT_EQ(names.size(), 6u);
  ASSERT_EQ(names, names_of(scratch / "jobs" / "database.db"));
  const auto a = ReadImageDescriptors(scratch / "local" / "database.db", names);
  const auto b = ReadImageDescriptors(scratch / "jobs" / "database.db", names);
  for (std::size_t i = 0; i < names.size(); ++i) {
    ASSERT_EQ(a[i].rows, b[i].rows) << names[i];
    EXPECT_EQ(cv::norm(a[i], b[i], cv::NORM_L1), 0) << names[i] << ": other descriptors";
  }
  // The same pairs verified, with the same inliers up to RANSAC's draws.
  const auto pairs_here = PairsByName(scratch / "local" / "database.db");
  const auto pairs_there = PairsByName(scratch / "jobs" / "database.db");
  EXPECT_NEAR(static_cast<double>(pairs_there.size()), static_cast<double>(pairs_here.size()), 0.05 * pairs_here.size());
  int same = 0, compared = 0;
  for (const auto& [pair, inliers] : pairs_here) {
    const auto it = pairs_there.find(pair);
    if (it == pairs_there.end()) continue;
    ++compared;
    same += it->second == inliers;
    EXPECT_NEAR(it->second, inliers, 0.1 * inliers + 2) << pair.first << " - " << pair.second;
  }
  std::cout << pairs_here.size() << " pairs verified here, " << pairs_there.size() << " in the jobs; " << same << " of "
            << compared << " with the same inliers\n";

  // Both maps register every frame, and are as close to the ground truth. (Not pose for pose: on
  // 6 frames with the fast preset COLMAP's mapper, given the same matches under other image ids,
  // built maps 0.9 degrees apart, each 1.3-2.3 degrees from the ground truth.)
  ASSERT_EQ(local.map.keyframes.size(), 6u);
  ASSERT_EQ(jobs.map.keyframes.size(), 6u);
  const auto truth = recordings::ReadTum(scratch / "recording" / "groundtruth.txt");
  const double error_here = recordings::EvaluateTrajectory(recordings::ReadTum(scratch / "local" / "keyframes.txt"), truth).ate.median;
  const double error_there = recordings::EvaluateTrajectory(recordings::ReadTum(scratch / "jobs" / "keyframes.txt"), truth).ate.median;
  std::cout << "centre error against the ground truth, median: local stages " << 1000 * error_here << " mm, jobs "
            << 1000 * error_there << " mm\n";
  // Within 1.5x of the local map's, or under 2 mm: right 6-frame maps differ from build to build
  // (above; 0.89 and 0.80 mm in one CI run), and two draws can land 1.5x apart at about a
  // millimetre, while features or matches lost or mixed up by the jobs put frames centimetres
  // off or leave them out.
  EXPECT_LT(error_there, std::max(1.5 * error_here, 0.002));
  if (!HasFailure()) fs::remove_all(scratch);  // kept to look at otherwise
}

}  // namespace
}  // namespace arview::mapping
