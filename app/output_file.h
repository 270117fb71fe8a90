#pragma once
// An output written under a temporary name and renamed into place only when complete, so that
// an interrupted or failed run never leaves a file that looks finished.

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace arview::app {

class PendingOutput {
 public:
  // "out.mp4" is written as "out.partial.mp4" (the extension kept: sinks choose by it). A PNG
  // folder "frames" (a path without extension) is written as "frames.partial/": an interrupted
  // run never leaves a folder of frames that looks complete.
  explicit PendingOutput(std::filesystem::path final_path) : final_(std::move(final_path)) {
    if (final_.filename().empty()) final_ = final_.parent_path();  // "frames/" names the folder
    folder_ = !final_.has_extension();
    partial_ = final_.parent_path() / (final_.stem().string() + ".partial" + final_.extension().string());
  }
  ~PendingOutput() {
    if (!committed_) {
      std::error_code ec;
      std::filesystem::remove_all(partial_, ec);
    }
  }
  PendingOutput(const PendingOutput&) = delete;
  PendingOutput& operator=(const PendingOutput&) = delete;

  const std::filesystem::path& partial() const { return partial_; }
  const std::filesystem::path& final_path() const { return final_; }
  // What to hand to render::OpenSink: a folder ends with '/' so that it is taken as one.
  std::string sink_target() const { return partial_.string() + (folder_ ? "/" : ""); }
  void Commit() {
    if (folder_ && std::filesystem::is_directory(final_)) {
      // An existing folder (a re-run): the new frames replace those of the same name.
      for (const auto& entry : std::filesystem::directory_iterator(partial_)) {
        std::filesystem::rename(entry.path(), final_ / entry.path().filename());
      }
      std::filesystem::remove(partial_);
    } else {
      std::filesystem::rename(partial_, final_);
    }
    committed_ = true;
  }

 private:
  std::filesystem::path final_, partial_;
  bool folder_ = false;
  bool committed_ = false;
};

// Writes `text` to a sibling temporary file and renames it into place; throws naming `file`.
inline void WriteTextFileAtomically(const std::filesystem::path& file, const std::string& text) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error(file.string() + ": cannot write here");
    out << text;
    if (!out) throw std::runtime_error(file.string() + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(file.string() + ": cannot write (" + ec.message() + ")");
  }
}

}  // namespace arview::app
