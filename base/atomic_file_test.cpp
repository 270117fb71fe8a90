#include "base/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>

#include <fstream>
#include <sstream>

#include "base/error.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("arview_atomic_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string Read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  size_t FilesInDir() const { return static_cast<size_t>(std::distance(fs::directory_iterator(dir_), {})); }

  fs::path dir_;
};

TEST_F(AtomicFileTest, WritesBinaryBytesExactlyAndLeavesNoTemporary) {
  const std::string bytes("a\0b\r\n\xff", 6);
  WriteFileAtomically(dir_ / "out.bin", bytes);
  EXPECT_EQ(Read(dir_ / "out.bin"), bytes);
  EXPECT_EQ(FilesInDir(), 1u);
}

TEST_F(AtomicFileTest, ReplacesAnExistingFile) {
  WriteFileAtomically(dir_ / "out.txt", "old");
  WriteFileAtomically(dir_ / "out.txt", "new text\n");
  EXPECT_EQ(Read(dir_ / "out.txt"), "new text\n");
}

TEST_F(AtomicFileTest, StreamingOverloadWritesWhatTheCallbackWrote) {
  WriteFileAtomically(dir_ / "s.txt", [](std::ostream& out) { out << "x = " << 42 << "\n"; });
  EXPECT_EQ(Read(dir_ / "s.txt"), "x = 42\n");
}

TEST_F(AtomicFileTest, ACallbackThatThrowsLeavesThePreviousFileUntouched) {
  WriteFileAtomically(dir_ / "keep.txt", "good");
  EXPECT_THROW(WriteFileAtomically(dir_ / "keep.txt",
                                   [](std::ostream& out) {
                                     out << "half";
                                     throw std::runtime_error("encoder failed");
                                   }),
               std::runtime_error);
  EXPECT_EQ(Read(dir_ / "keep.txt"), "good");
  EXPECT_EQ(FilesInDir(), 1u);
}

TEST_F(AtomicFileTest, AMissingFolderThrowsAnErrorNamingTheFinalFile) {
  const fs::path file = dir_ / "no" / "such" / "out.txt";
  try {
    WriteFileAtomically(file, "x");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
}

TEST_F(AtomicFileTest, AFailedRenameRemovesTheTemporaryAndNamesTheFile) {
  // A directory where the file should go: the data is written, the rename fails.
  fs::create_directories(dir_ / "taken" / "inside");
  try {
    WriteFileAtomically(dir_ / "taken", "x");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find((dir_ / "taken").string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(FilesInDir(), 1u);  // only the directory: no temporary left
}

// Runs `body` under a file-size limit of 4 KiB: write() fails with EFBIG part way (SIGXFSZ
// ignored so that it returns instead of killing the process), as a full disk would.
template <class Body>
void UnderA4KiBFileSizeLimit(Body body) {
  struct rlimit old {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old;
  small.rlim_cur = 4096;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  body();
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
}

TEST_F(AtomicFileTest, AFailedWriteIsAnErrorAndLeavesNeitherFileNorTemporary) {
  bool threw = false;
  std::string message;
  UnderA4KiBFileSizeLimit([&] {
    try {
      WriteFileAtomically(dir_ / "big.bin", std::string(100000, 'x'));
    } catch (const Error& e) {
      threw = true;
      message = e.what();
    }
  });
  EXPECT_TRUE(threw);
  EXPECT_NE(message.find((dir_ / "big.bin").string()), std::string::npos) << message;
  EXPECT_EQ(FilesInDir(), 0u);
}

// The probe arview map uses when COLMAP fails: room, a file-size limit of 4 KiB (the probe's
// write fails part way: the second write says why), a missing folder; no probe file left.
TEST_F(AtomicFileTest, NoRoomToWriteSaysWhyAndLeavesNoProbe) {
  EXPECT_EQ(NoRoomToWrite(dir_), "");
  std::string limited;
  UnderA4KiBFileSizeLimit([&] { limited = NoRoomToWrite(dir_); });
  EXPECT_EQ(limited, "File too large");
  EXPECT_EQ(NoRoomToWrite(dir_ / "missing"), "No such file or directory");
  EXPECT_EQ(FilesInDir(), 0u);
}

TEST_F(AtomicFileTest, PendingOutputRenamesOnCommitOnly) {
  {
    PendingOutput out(dir_ / "video.mp4");
    EXPECT_EQ(out.partial(), dir_ / "video.partial.mp4");
    std::ofstream(out.partial()) << "frames";
    out.Commit();
    EXPECT_TRUE(out.committed());
  }
  EXPECT_EQ(Read(dir_ / "video.mp4"), "frames");
  EXPECT_FALSE(fs::exists(dir_ / "video.partial.mp4"));
}

TEST_F(AtomicFileTest, PendingOutputNeverCommittedRemovesThePartialFile) {
  {
    PendingOutput out(dir_ / "video.mp4");
    std::ofstream(out.partial()) << "half";
  }
  EXPECT_EQ(FilesInDir(), 0u);
}

TEST_F(AtomicFileTest, PendingOutputCommitWithNothingWrittenThrows) {
  PendingOutput out(dir_ / "video.mp4");
  EXPECT_THROW(out.Commit(), Error);
  EXPECT_FALSE(fs::exists(dir_ / "video.mp4"));
}

TEST_F(AtomicFileTest, PendingFolderIsRenamedOnCommitAndMergedIntoAnExistingOne) {
  {
    PendingOutput out(dir_ / "frames/");
    EXPECT_EQ(out.partial(), dir_ / "frames.partial");
    EXPECT_EQ(out.sink_target(), (dir_ / "frames.partial").string() + "/");
    fs::create_directories(out.partial());
    std::ofstream(out.partial() / "000000.png") << "a";
    out.Commit();
  }
  {
    PendingOutput again(dir_ / "frames");
    fs::create_directories(again.partial());
    std::ofstream(again.partial() / "000000.png") << "b";
    again.Commit();
  }
  EXPECT_EQ(Read(dir_ / "frames" / "000000.png"), "b");
  EXPECT_FALSE(fs::exists(dir_ / "frames.partial"));
}

TEST_F(AtomicFileTest, PendingFolderNeverCommittedIsRemovedWithItsFiles) {
  {
    PendingOutput out(dir_ / "frames");
    fs::create_directories(out.partial());
    std::ofstream(out.partial() / "000000.png") << "half";
  }
  EXPECT_EQ(FilesInDir(), 0u);
}

}  // namespace
}  // namespace arview
