#include "base/atomic_file.h"

#include <sys/stat.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>
#include <system_error>

#include "base/error.h"
#include "base/input_guard.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

// A sibling of `file` that no concurrent writer of the same file picks too.
fs::path TemporaryFor(const fs::path& file) {
  return file.string() + ".tmp." + std::to_string(::getpid());
}

std::string Reason(int err) { return std::strerror(err); }

// Writes everything, retrying short writes and EINTR; returns 0 or the errno.
int WriteAll(int fd, std::string_view bytes) {
  const char* p = bytes.data();
  size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  return 0;
}

[[noreturn]] void Fail(const fs::path& file, const fs::path& tmp, const std::string& what) {
  std::error_code ec;
  fs::remove(tmp, ec);
  throw Error(file.string() + ": cannot write (" + what + ")");
}

// An output path that is there already must be a regular file (or, for a folder output, a
// folder): renaming over a device, a FIFO or a socket would replace it (as root, `--out
// /dev/full` replaced the device node with a regular file).
void RequireReplaceable(const fs::path& file, bool folder_allowed) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return;  // not there (or a dangling link): written new
  if (S_ISREG(st.st_mode) || (folder_allowed && S_ISDIR(st.st_mode))) return;
  throw Error(file.string() + ": is " + FileKindOf(st.st_mode) + ", not a file arview may replace (give a file path)");
}

}  // namespace

void WriteFileAtomically(const fs::path& file, std::string_view bytes) {
  RequireReplaceable(file, false);
  const fs::path tmp = TemporaryFor(file);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(file.string() + ": cannot write here (" + Reason(errno) + ")");
  if (const int err = WriteAll(fd, bytes)) {
    ::close(fd);
    Fail(file, tmp, Reason(err));
  }
  // The data must be on disk before the rename makes it the file: otherwise a crash right after
  // could leave the new name pointing at an empty file.
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    Fail(file, tmp, "fsync: " + Reason(err));
  }
  if (::close(fd) != 0) Fail(file, tmp, "close: " + Reason(errno));
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) Fail(file, tmp, ec.message());
}

void WriteFileAtomically(const fs::path& file, const std::function<void(std::ostream&)>& write) {
  std::ostringstream buffer(std::ios::binary);
  write(buffer);
  WriteFileAtomically(file, buffer.view());
}

PendingOutput::PendingOutput(fs::path final_path) : final_(std::move(final_path)) {
  if (final_.filename().empty()) final_ = final_.parent_path();  // "frames/" names the folder
  folder_ = !final_.has_extension();
  partial_ = final_.parent_path() / (final_.stem().string() + ".partial" + final_.extension().string());
  RequireReplaceable(final_, folder_);
}

PendingOutput::~PendingOutput() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(partial_, ec);
  }
}

void PendingOutput::Commit() {
  std::error_code ec;
  if (!fs::exists(partial_, ec)) throw Error(final_.string() + ": cannot write (nothing was written)");
  if (folder_ && fs::is_directory(final_, ec)) {
    for (const auto& entry : fs::directory_iterator(partial_, ec)) {
      fs::rename(entry.path(), final_ / entry.path().filename(), ec);
      if (ec) break;
    }
    if (!ec) fs::remove(partial_, ec);
  } else {
    fs::rename(partial_, final_, ec);
  }
  if (ec) {
    std::error_code ignored;
    fs::remove_all(partial_, ignored);
    throw Error(final_.string() + ": cannot write (" + ec.message() + ")");
  }
  committed_ = true;
}

StreamedFile::StreamedFile(const fs::path& file, std::string_view role) : pending_(file) {
  std::error_code ec;
  if (fs::is_directory(pending_.final_path(), ec)) {
    throw Error(pending_.final_path().string() + ": is a folder, not a file for " + std::string(role) +
                " (give a file path)");
  }
  file_ = std::fopen(pending_.partial().c_str(), "w");
  if (file_ == nullptr) throw Error(pending_.final_path().string() + ": cannot write here (" + std::strerror(errno) + ")");
}

StreamedFile::~StreamedFile() {
  if (file_ != nullptr) std::fclose(file_);  // unfinished: PendingOutput removes the partial file
}

void StreamedFile::Write(std::string_view text) {
  if (file_ == nullptr) throw Error(pending_.final_path().string() + ": cannot write (already finished)");
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || std::fflush(file_) != 0) {
    throw Error(pending_.final_path().string() + ": cannot write (" + std::strerror(errno) + ")");
  }
}

void StreamedFile::Finish() {
  if (file_ == nullptr) throw Error(pending_.final_path().string() + ": cannot write (already finished)");
  // On disk before the rename makes it the file (as WriteFileAtomically).
  const bool synced = ::fsync(::fileno(file_)) == 0;
  const int sync_error = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!synced || !closed) {
    throw Error(pending_.final_path().string() + ": cannot write (" + std::strerror(synced ? errno : sync_error) + ")");
  }
  pending_.Commit();
}

std::string NoRoomToWrite(const std::filesystem::path& folder) {
  const std::filesystem::path probe = folder / (".arview-space-probe." + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return std::strerror(errno);
  constexpr size_t kProbeBytes = 1 << 20;
  const std::string zeros(kProbeBytes, '\0');
  int error = 0;
  // A short write is the disk filling up: the next one says why.
  for (size_t done = 0; done < kProbeBytes && error == 0;) {
    const ssize_t n = ::write(fd, zeros.data() + done, kProbeBytes - done);
    if (n < 0 && errno != EINTR) error = errno;
    if (n == 0) error = ENOSPC;
    if (n > 0) done += static_cast<size_t>(n);
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return error != 0 ? std::strerror(error) : std::string();
}

}  // namespace arview
