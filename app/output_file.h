#pragma once
// An output written under a temporary name and renamed into place only when complete, so that
// an interrupted or failed run never leaves a file that looks finished.

#include <filesystem>
#include <string>

namespace arview::app {

class PendingOutput {
 public:
  // "out.mp4" is written as "out.partial.mp4" (the extension kept: sinks choose by it).
  explicit PendingOutput(std::filesystem::path final_path) : final_(std::move(final_path)) {
    partial_ = final_.parent_path() / (final_.stem().string() + ".partial" + final_.extension().string());
  }
  ~PendingOutput() {
    if (!committed_) {
      std::error_code ec;
      std::filesystem::remove(partial_, ec);
    }
  }
  PendingOutput(const PendingOutput&) = delete;
  PendingOutput& operator=(const PendingOutput&) = delete;

  const std::filesystem::path& partial() const { return partial_; }
  const std::filesystem::path& final_path() const { return final_; }
  void Commit() {
    std::filesystem::rename(partial_, final_);
    committed_ = true;
  }

 private:
  std::filesystem::path final_, partial_;
  bool committed_ = false;
};

}  // namespace arview::app
