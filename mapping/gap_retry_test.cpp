// The retry for a stretch COLMAP left out (mapping/gap_retry.h): which frames count as a stretch,
// and which model stays in <out>/sparse after the retry, with a stand-in for COLMAP's mapper.
#include "mapping/gap_retry.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "base/cancellation.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

map::Map MapOfFrames(const std::vector<int>& frames) {
  map::Map map;
  for (int f : frames) {
    map::Keyframe k;
    k.frame_index = f;
    map.keyframes.push_back(k);
  }
  return map;
}

// Every fourth frame from 0 to 296, as the rendered room's 75-frame map selects them.
std::vector<int> EveryFourth() {
  std::vector<int> frames;
  for (int f = 0; f <= 296; f += 4) frames.push_back(f);
  return frames;
}

std::vector<int> FramesUpTo(int last) {
  std::vector<int> frames;
  for (int f = 0; f <= last; f += 4) frames.push_back(f);
  return frames;
}

TEST(LeftOutStretches, TheWalkAfterTheTurnIsOneStretch) {
  const auto stretches = LeftOutStretches(EveryFourth(), MapOfFrames(FramesUpTo(176)), 3);
  ASSERT_EQ(stretches.size(), 1u);
  EXPECT_EQ(stretches[0].first, 180);
  EXPECT_EQ(stretches[0].last, 296);
  EXPECT_EQ(stretches[0].count, 30);
}

TEST(LeftOutStretches, AFrameMissingAloneIsNoStretchButAStartAndAMiddleAre) {
  std::vector<int> registered;
  for (int f : EveryFourth())
    if (f != 40 && (f < 100 || f > 108) && f > 8) registered.push_back(f);
  const auto stretches = LeftOutStretches(EveryFourth(), MapOfFrames(registered), 3);
  ASSERT_EQ(stretches.size(), 2u);
  EXPECT_EQ(stretches[0].first, 0);
  EXPECT_EQ(stretches[0].last, 8);
  EXPECT_EQ(stretches[1].first, 100);
  EXPECT_EQ(stretches[1].count, 3);
  EXPECT_EQ(LeftOutStretches(EveryFourth(), MapOfFrames(registered), 1).size(), 3u);
  EXPECT_TRUE(LeftOutStretches(EveryFourth(), MapOfFrames(EveryFourth()), 1).empty());
}

TEST(LowAngleMapperArgs, LowersBothTriangulationAngles) {
  EXPECT_EQ(LowAngleMapperArgs(0.5),
            (std::vector<std::string>{"--Mapper.tri_min_angle", "0.50", "--Mapper.filter_min_tri_angle", "0.50"}));
}

// A map folder whose sparse/ holds a file naming the model, and a mapper that writes the next one.
class GapRetry : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() / ("arview_gap_retry_" + std::to_string(::getpid()));
    fs::remove_all(out_);
    WriteModel("first");
    result_.selected_frames = EveryFourth();
    result_.map = MapOfFrames(FramesUpTo(176));
  }
  void TearDown() override { fs::remove_all(out_); }

  void WriteModel(const std::string& name) {
    fs::create_directories(out_ / "sparse");
    std::ofstream(out_ / "sparse" / "model") << name;
  }
  std::string ModelInPlace() const {
    std::ifstream in(out_ / "sparse" / "model");
    std::string name;
    in >> name;
    return name;
  }
  // The retry's mapper registers `frames`; read_model reads whichever model is in sparse/.
  FoldRetryStages Stages(const std::vector<int>& retry_frames) {
    return {[this](const std::vector<std::string>& args) {
              mapper_args_.push_back(args);
              WriteModel("retry");
            },
            [this, retry_frames] {
              result_.map = MapOfFrames(ModelInPlace() == "retry" ? retry_frames : FramesUpTo(176));
            },
            [this] { remembered_ = false; }, [this] { remembered_ = true; }};
  }

  fs::path out_;
  MapBuildResult result_;
  std::vector<std::vector<std::string>> mapper_args_;
  bool remembered_ = true;
  std::vector<std::string> notes_;
  MapBuildCallbacks cb_{{}, [this](const std::string& note) { notes_.push_back(note); }, {}};
};

TEST_F(GapRetry, KeepsTheRetrysModelWhenItRegistersTheWalkAfterTheTurn) {
  MapBuildOptions options;
  const auto kept = RetryLeftOutFrames(options, out_, cb_, Stages(EveryFourth()), &result_);
  EXPECT_EQ(kept, LowAngleMapperArgs(0.5));
  ASSERT_EQ(mapper_args_.size(), 1u);
  EXPECT_EQ(mapper_args_[0], LowAngleMapperArgs(0.5));
  EXPECT_EQ(ModelInPlace(), "retry");
  EXPECT_EQ(result_.map.keyframes.size(), 75u);
  EXPECT_TRUE(remembered_);
  EXPECT_FALSE(fs::exists(out_ / "gap-try"));
  ASSERT_EQ(notes_.size(), 2u);
  EXPECT_NE(notes_[0].find("registered 45 of 75 frames and left out frames 180-296 (30)"), std::string::npos)
      << notes_[0];
  EXPECT_NE(notes_[1].find("mapping again registered 75 of 75 frames"), std::string::npos) << notes_[1];
}

TEST_F(GapRetry, PutsTheFirstModelBackWhenTheRetryRegistersNoMore) {
  MapBuildOptions options;
  const auto kept = RetryLeftOutFrames(options, out_, cb_, Stages(FramesUpTo(172)), &result_);
  EXPECT_TRUE(kept.empty());
  EXPECT_EQ(ModelInPlace(), "first");
  EXPECT_EQ(result_.map.keyframes.size(), 45u);
  EXPECT_TRUE(remembered_);
  EXPECT_FALSE(fs::exists(out_ / "gap-try"));
  ASSERT_EQ(notes_.size(), 2u);
  EXPECT_NE(notes_[1].find("the first model (45) is kept"), std::string::npos) << notes_[1];
}

TEST_F(GapRetry, PutsTheFirstModelBackWhenCancelled) {
  MapBuildOptions options;
  FoldRetryStages stages = Stages(EveryFourth());
  stages.map = [](const std::vector<std::string>&) { throw CancelledError("stopped", 2); };
  EXPECT_THROW(RetryLeftOutFrames(options, out_, cb_, stages, &result_), CancelledError);
  EXPECT_EQ(ModelInPlace(), "first");
  EXPECT_TRUE(remembered_);
}

TEST_F(GapRetry, RunsNothingForAWholeMapOrWhenTurnedOff) {
  MapBuildOptions options;
  result_.map = MapOfFrames(EveryFourth());
  EXPECT_TRUE(RetryLeftOutFrames(options, out_, cb_, Stages(EveryFourth()), &result_).empty());
  result_.map = MapOfFrames(FramesUpTo(176));
  options.gap_retry_angle_deg = 0;
  EXPECT_TRUE(RetryLeftOutFrames(options, out_, cb_, Stages(EveryFourth()), &result_).empty());
  EXPECT_TRUE(mapper_args_.empty());
  EXPECT_TRUE(notes_.empty());
  EXPECT_EQ(ModelInPlace(), "first");
}

}  // namespace
}  // namespace arview::mapping
