// The appliance end to end on real data: templeRing mapped from its even frames, a character
// placed on the temple's base, the odd frames replayed through the whole pipeline.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "map/map_file.h"
#include "mapping/map_check.h"
#include "tests/support/run_command.h"
#include "tests/support/test_data.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::RunArview;

// `arview map` again on the same inputs: COLMAP's stages are reused, so only arview's own writes
// after COLMAP (check.json, keyframes.txt, map.png, map.arvmap, in that order) meet the full disk
// (issue 17 §6; a file-size limit stands in for it, as in faults_test.cpp). Under a limit of 0,
// and under one that lets every file but map.arvmap through: one line naming the file and the
// cause, no map.arvmap (a disk that fills at an earlier file must not leave a new map beside
// the error), no temporary, COLMAP's stages kept; then, with room again, the same map.
void ExpectMapOnADiskThatFillsAfterColmapToFailCleanly(const fs::path& dir) {
  const fs::path map_dir = dir / "map";
  const fs::path map_file = map_dir / map::kMapFileName;
  const std::string first_map = testing::ReadWholeFile(map_file.string());
  ASSERT_FALSE(first_map.empty());
  std::uintmax_t largest_other = 0;
  for (const char* name : {mapping::kMapCheckFileName, "keyframes.txt", "map.png"}) {
    largest_other = std::max(largest_other, fs::file_size(map_dir / name));
  }
  const std::uintmax_t fits_all_but_the_map = (largest_other + 511) / 512;  // ulimit -f counts 512-byte blocks
  ASSERT_LT(fits_all_but_the_map * 512, first_map.size()) << "map.arvmap should be the largest file";
  const char* bin = std::getenv("ARVIEW_BIN");
  for (std::uintmax_t blocks : {std::uintmax_t{0}, fits_all_but_the_map}) {
    const std::string label = "limit " + std::to_string(blocks) + " blocks: ";
    for (const char* name : {map::kMapFileName, mapping::kMapCheckFileName, "keyframes.txt", "map.png"}) {
      fs::remove(map_dir / name);
    }
    const fs::path err_file = dir / "full.err", code_file = dir / "full.code";
    const std::string inner = "trap '' XFSZ; ulimit -f " + std::to_string(blocks) + "; exec " +
                              testing::ShellQuote(bin ? bin : "arview") + " map " +
                              testing::ShellQuote((dir / "temple").string()) + " --out " +
                              testing::ShellQuote(map_dir.string()) + " --frames 0-46:2 --no-metric";
    const std::string cmd = "{ sh -c " + testing::ShellQuote(inner) + "; echo $? >" +
                            testing::ShellQuote(code_file.string()) + "; } 2>&1 >/dev/null </dev/null | cat >" +
                            testing::ShellQuote(err_file.string());
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const int code = std::stoi(testing::ReadWholeFile(code_file.string()));
    const std::string err = testing::ReadWholeFile(err_file.string());
    EXPECT_NE(code, 0) << label << err;
    EXPECT_EQ(err.find("COLMAP"), std::string::npos) << label << "COLMAP ran again, or was blamed: " << err;
    size_t error_lines = 0, last = std::string::npos;
    for (size_t at = err.find("arview: "); at != std::string::npos; at = err.find("arview: ", at + 1)) {
      ++error_lines;
      last = at;
    }
    ASSERT_EQ(error_lines, 1u) << label << err;
    const std::string line = err.substr(last, err.find('\n', last) - last);
    EXPECT_EQ(line.rfind("arview: " + map_dir.string() + "/", 0), 0u) << label << line;
    EXPECT_NE(line.find("File too large"), std::string::npos) << label << line;
    if (blocks > 0) {
      EXPECT_NE(line.find(map::kMapFileName), std::string::npos) << label << line;
    }
    EXPECT_FALSE(fs::exists(map_file)) << label << "a new map.arvmap beside the error";
    std::error_code ec;
    for (const auto& e : fs::recursive_directory_iterator(map_dir, ec)) {
      EXPECT_NE(e.path().extension(), ".tmp") << label << e.path() << " left";
    }
    EXPECT_TRUE(fs::exists(map_dir / "stages" / "map.inputs")) << label << "COLMAP's finished stages must be kept";
  }
  const auto again =
      RunArview({"map", (dir / "temple").string(), "--out", map_dir.string(), "--frames", "0-46:2", "--no-metric"});
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(testing::ReadWholeFile(map_file.string()) == first_map) << "the map re-made from the kept stages differs";
}

TEST(Appliance, TempleRingReplayCompositesEveryFrameAndTheHeadFollowsTheCamera) {
  const fs::path temple = testing::SharedData("templeRing");
  ARVIEW_REQUIRE_DATA_PATH(temple, "../shared/data");
  ARVIEW_REQUIRE_DATA_PATH("/usr/share/assimp/models/X/BCN_Epileptic.X", "Debian package assimp-testmodels");
  const fs::path dir = fs::temp_directory_path() / ("arview_appliance_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);

  auto run = [](const std::vector<std::string>& args) {
    const auto r = RunArview(args);
    EXPECT_EQ(r.exit_code, 0) << args[0] << ": " << r.err;
    return r;
  };
  run({"import", "middlebury", temple.string(), "--out", (dir / "temple").string()});
  // COLMAP's frame: --height below is a fraction of the viewing distance (a temple on a table has
  // no floor a hand-held camera height could scale).
  run({"map", (dir / "temple").string(), "--out", (dir / "map").string(), "--frames", "0-46:2", "--no-metric"});
  run({"place", (dir / "map").string(), "--character", "/usr/share/assimp/models/X/BCN_Epileptic.X", "--base-clip",
       "rest", "--height", "0.2", "--out", (dir / "scene.yaml").string()});
  const auto replay = run({"replay", (dir / "temple").string(), "--map", (dir / "map").string(), "--scene",
                           (dir / "scene.yaml").string(), "--frames", "1-46:2", "--out", (dir / "out.mp4").string(),
                           "--stats", (dir / "stats.json").string(), "--trajectory", (dir / "traj.txt").string()});
  if (HasFailure()) return;

  std::cout << replay.out;
  cv::VideoCapture video((dir / "out.mp4").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  for (cv::Mat f; video.read(f);) ++frames;
  EXPECT_EQ(frames, 23) << "every odd frame composited";
  EXPECT_FALSE(fs::exists(dir / "out.partial.mp4"));

  const std::string stats = testing::ReadWholeFile((dir / "stats.json").string());
  std::smatch m;
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("frames_processed": (\d+))")));
  EXPECT_EQ(std::stoi(m[1]), 23);
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("frames_localized": (\d+))")));
  EXPECT_EQ(std::stoi(m[1]), 23);
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("frames_within_20_deg": (\d+))")));
  EXPECT_EQ(std::stoi(m[1]), 23) << "the blended head's forward axis within 20 deg of the camera centre";
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("max_error_deg": ([0-9.]+))")));
  EXPECT_LE(std::stod(m[1]), 20.0);

  // What the viewer sees, from the replay's own files: the character's anchor and box corners
  // projected with the estimated and the true pose, the smoothed centres read from its stats.
  // Only the frames before templeR0032: from there on the data's true rotations are turned 180°
  // about the optical axis against what the images show (COLMAP's own keyframes as well as the
  // tracked frames; docs/tracker.md, "Seventh round"), and would score hundreds of pixels.
  const fs::path upright_truth = dir / "groundtruth_to_0031.txt";
  {
    std::ifstream in(dir / "temple" / "groundtruth.txt");
    std::ofstream out(upright_truth);
    for (std::string line; std::getline(in, line);) {
      if (!line.empty() && line[0] != '#' && std::stod(line) > 30.5) continue;  // timestamps are frame indices
      out << line << "\n";
    }
  }
  const auto seen = run({"eval", (dir / "traj.txt").string(), upright_truth.string(), "--align-with",
                         (dir / "map" / "keyframes.txt").string(), "--camera", (dir / "temple" / "camera.yaml").string(),
                         "--scene", (dir / "scene.yaml").string(), "--smoothed", (dir / "stats.json").string()});
  EXPECT_NE(seen.out.find("registration 9 points, 15 frames"), std::string::npos) << seen.out;
  EXPECT_NE(seen.out.find("smoothing   lags the raw centre by"), std::string::npos) << seen.out;
  ASSERT_TRUE(std::regex_search(seen.out, m, std::regex(R"(mean per frame median ([0-9.]+) px)"))) << seen.out;
  // A fresh COLMAP map each run: on four default maps of the even frames the median was 4.9-5.4 px,
  // most of it the ~0.2° between the map's orientation and the data's (f = 1520 px).
  EXPECT_LT(std::stod(m[1]), 7.0) << "templeRing's poses are within a few mm and tenths of a degree";
  ASSERT_TRUE(std::regex_search(seen.out, m, std::regex(R"(mean per frame median [0-9.]+ px  p95 [0-9.]+ px  max ([0-9.]+) px)")))
      << seen.out;
  EXPECT_LT(std::stod(m[1]), 30.0) << "no frame far off";

  // The HUD is drawn on the sink's thread (FrameCompositor::DeferredOverlay): the same frames
  // with and without it differ, and only in the HUD's places, the character's pixels the same.
  for (const char* name : {"plain", "hud"}) {
    std::vector<std::string> args = {"replay", (dir / "temple").string(), "--map", (dir / "map").string(), "--scene",
                                     (dir / "scene.yaml").string(), "--frames", "1-5:2", "--out", (dir / name).string()};
    if (std::string(name) == "hud") args.push_back("--hud");
    run(args);
  }
  if (HasFailure()) return;
  for (const char* frame : {"000000.png", "000002.png"}) {
    const cv::Mat plain = cv::imread((dir / "plain" / frame).string()), hud = cv::imread((dir / "hud" / frame).string());
    ASSERT_FALSE(plain.empty()) << frame;
    ASSERT_EQ(plain.size(), hud.size()) << frame;
    cv::Mat differs;
    cv::cvtColor(cv::abs(plain - hud) + cv::abs(hud - plain), differs, cv::COLOR_BGR2GRAY);
    const int changed = cv::countNonZero(differs);
    EXPECT_GT(changed, 500) << frame << ": no HUD drawn";
    EXPECT_LT(changed, plain.total() / 2) << frame << ": the HUD changed most of the picture";
  }

  ExpectMapOnADiskThatFillsAfterColmapToFailCleanly(dir);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview
