#pragma once
// Files that appear complete or not at all. Every file arview owns (maps, trajectories,
// recordings, camera files, stats, scenes, images) is written to a sibling temporary, every
// write and the final flush and close are checked, the data is fsync'ed, and only then is the
// temporary renamed over the final name. A failure at any step removes the temporary and throws
// an arview::Error naming the final file: an interrupted or failed run never leaves a file that
// looks finished, and never destroys the previous good copy.

#include <cstdio>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>

namespace arview {

// Writes `bytes` (text or binary, written as is) to `file` atomically.
void WriteFileAtomically(const std::filesystem::path& file, std::string_view bytes);

// Streams into memory through `write`, then writes the result atomically. An exception from
// `write` propagates and nothing is written.
void WriteFileAtomically(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write);

// Why `folder` has no room for 1 MiB more (strerror's text: "No space left on device", "Disk
// quota exceeded", "File too large" under a file-size limit), or "" when it has: a probe file of
// that size is written there (and removed). For a child process that failed writing there
// (COLMAP's SQLite says only "disk I/O error"), so that the cause is said in one line.
std::string NoRoomToWrite(const std::filesystem::path& folder);

// An output that a library other than ours writes (a video encoder, COLMAP, a sink that grows
// frame by frame) under a partial name; renamed into place by Commit() once complete, removed
// on destruction if never committed.
class PendingOutput {
 public:
  // "out.mp4" is written as "out.partial.mp4": the extension is kept, as writers choose their
  // format by it. A folder of frames "frames" (a path without extension, or ending in '/') is
  // written as "frames.partial/": an interrupted run never leaves a folder that looks complete.
  explicit PendingOutput(std::filesystem::path final_path);
  ~PendingOutput();
  PendingOutput(const PendingOutput&) = delete;
  PendingOutput& operator=(const PendingOutput&) = delete;

  const std::filesystem::path& partial() const { return partial_; }
  const std::filesystem::path& final_path() const { return final_; }
  bool committed() const { return committed_; }
  // What to hand to a sink that chooses file or folder by the name: a folder ends with '/'.
  std::string sink_target() const { return partial_.string() + (folder_ ? "/" : ""); }
  // Renames the partial file over the final one (a partial folder's files into an existing final
  // folder: a re-run replaces frames of the same name); throws arview::Error naming the final file
  // (and removes the partial) if the partial file is missing or the rename fails.
  void Commit();

 private:
  std::filesystem::path final_, partial_;
  bool folder_ = false;
  bool committed_ = false;
};

// A file written piece by piece as a long run goes (a session's --stats and --trajectory), so
// that what it holds is on disk and not in memory: under PendingOutput's partial name, each
// piece flushed to the kernel (a run killed outright leaves it readable in the partial file),
// fsync'ed and renamed into place by Finish(); removed if destroyed unfinished. From one thread
// at a time.
class StreamedFile {
 public:
  // Throws arview::Error naming `file` when it is a folder (`role`: what the file is for, as
  // "--stats") or cannot be written.
  StreamedFile(const std::filesystem::path& file, std::string_view role);
  ~StreamedFile();
  StreamedFile(const StreamedFile&) = delete;
  StreamedFile& operator=(const StreamedFile&) = delete;

  // Throws arview::Error naming the file when the write fails.
  void Write(std::string_view text);
  void Finish();

 private:
  PendingOutput pending_;
  std::FILE* file_ = nullptr;
};

}  // namespace arview
