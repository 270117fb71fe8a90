#include "base/process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <sstream>
#include <thread>

extern char** environ;

namespace arview {

namespace {

// Closes a file descriptor once, on every exit path.
struct Fd {
  int fd = -1;
  ~Fd() { Close(); }
  void Close() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

// Gathers a byte stream into lines (COLMAP ends some progress lines with '\r').
class LineSplitter {
 public:
  template <typename F>
  void Feed(const char* data, size_t n, F&& emit) {
    for (size_t i = 0; i < n; ++i) {
      const char c = data[i];
      if (c == '\n' || c == '\r') {
        if (!pending_.empty()) emit(pending_);
        pending_.clear();
      } else {
        pending_.push_back(c);
      }
    }
  }
  template <typename F>
  void Flush(F&& emit) {
    if (!pending_.empty()) emit(pending_);
    pending_.clear();
  }

 private:
  std::string pending_;
};

// Waits for `pid` without blocking longer than `budget`; true when it was reaped.
bool ReapWithin(pid_t pid, std::chrono::milliseconds budget, int* status) {
  const auto deadline = std::chrono::steady_clock::now() + budget;
  for (;;) {
    const pid_t r = ::waitpid(pid, status, WNOHANG);
    if (r == pid || (r < 0 && errno == ECHILD)) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// SIGTERM to the child's whole group, SIGKILL to whatever is left after the grace period.
void StopChildGroup(pid_t pid, std::chrono::milliseconds grace) {
  ::kill(-pid, SIGTERM);
  int status = 0;
  const bool exited = ReapWithin(pid, grace, &status);
  ::kill(-pid, SIGKILL);  // the leader may have exited while helpers in its group still run
  if (!exited) {
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
}

std::string Joined(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

// In the child, between fork() and exec(): only async-signal-safe calls. Reports a failure
// as its errno on `error_fd` (close-on-exec: a successful exec closes it with nothing written).
[[noreturn]] void ExecChild(const char* exe, char* const* argv, pid_t parent, int output_fd, int error_fd) {
  ::setpgid(0, 0);
  // Die with arview, however arview dies; then check that it did not die already.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);
  ::signal(SIGINT, SIG_DFL);
  ::signal(SIGTERM, SIG_DFL);
  ::signal(SIGPIPE, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  const int null_fd = ::open("/dev/null", O_RDONLY);
  if (null_fd >= 0) ::dup2(null_fd, 0);
  ::dup2(output_fd, 1);
  ::dup2(output_fd, 2);
  ::execve(exe, argv, environ);
  const int err = errno;
  [[maybe_unused]] ssize_t n = ::write(error_fd, &err, sizeof err);
  ::_exit(127);
}

}  // namespace

std::string FindExecutable(const std::string& program) {
  auto executable = [](const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
  };
  if (program.find('/') != std::string::npos) return executable(program) ? program : "";
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
    if (executable(candidate)) return candidate;
  }
  return "";
}

ProcessResult RunProcess(const std::vector<std::string>& argv, const std::filesystem::path& log_path,
                         const std::function<void(const std::string&)>& on_line, const CancellationToken& cancel,
                         const ProcessOptions& options) {
  if (argv.empty()) throw ProcessError("RunProcess: empty command");
  cancel.ThrowIfCancelled("not starting " + argv[0]);
  const std::string exe = FindExecutable(argv[0]);
  if (exe.empty()) throw ProcessError("'" + argv[0] + "' not found on PATH");

  std::ofstream log(log_path, std::ios::app);
  if (!log) throw ProcessError(log_path.string() + ": cannot open the log file for writing");
  log << "$ " << Joined(argv) << "\n";

  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw ProcessError(std::string("pipe: ") + std::strerror(errno));
  Fd read_end{pipe_fds[0]};
  Fd write_end{pipe_fds[1]};
  int error_fds[2];
  if (::pipe2(error_fds, O_CLOEXEC) != 0) throw ProcessError(std::string("pipe: ") + std::strerror(errno));
  Fd error_read{error_fds[0]};
  Fd error_write{error_fds[1]};

  // Everything the child needs is built before fork(): it may not allocate.
  std::vector<char*> cargv;
  for (const auto& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw ProcessError("cannot start '" + exe + "': " + std::strerror(errno));
  if (pid == 0) ExecChild(exe.c_str(), cargv.data(), parent, write_end.fd, error_write.fd);
  ::setpgid(pid, pid);  // also here: a StopChildGroup right after fork must reach the group
  write_end.Close();
  error_write.Close();
  int exec_errno = 0;
  ssize_t got = 0;
  while ((got = ::read(error_read.fd, &exec_errno, sizeof exec_errno)) < 0 && errno == EINTR) {
  }
  if (got > 0) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    throw ProcessError("cannot start '" + exe + "': " + std::strerror(exec_errno));
  }

  ProcessResult result;
  std::deque<std::string> tail;
  LineSplitter splitter;
  auto emit = [&](const std::string& line) {
    log << line << "\n";
    tail.push_back(line);
    if (tail.size() > options.tail_lines) tail.pop_front();
    if (on_line) on_line(line);
  };
  auto stop_if_cancelled = [&] {
    if (!cancel.IsCancelled()) return;
    StopChildGroup(pid, options.stop_grace);
    log << "(" << cancel.Reason() << ": stopped)\n";
    cancel.ThrowIfCancelled("stopped " + argv[0] + (argv.size() > 1 ? " " + argv[1] : ""));
  };
  char buffer[4096];
  for (;;) {
    stop_if_cancelled();
    pollfd p{read_end.fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, 100);
    if (ready <= 0) continue;  // timeout or EINTR (a signal): look at the token again
    const ssize_t n = ::read(read_end.fd, buffer, sizeof buffer);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) break;  // EOF: the child closed its output (normally: exited)
    try {
      splitter.Feed(buffer, static_cast<size_t>(n), emit);
    } catch (...) {
      StopChildGroup(pid, options.stop_grace);
      throw;
    }
  }
  splitter.Flush(emit);

  int status = 0;
  while (!ReapWithin(pid, std::chrono::milliseconds(100), &status)) stop_if_cancelled();
  if (WIFSIGNALED(status)) {
    result.signaled = true;
    result.signal = WTERMSIG(status);
  } else {
    result.exit_code = WEXITSTATUS(status);
  }
  result.tail.assign(tail.begin(), tail.end());
  log << "(exit " << (result.signaled ? "signal " + std::to_string(result.signal) : std::to_string(result.exit_code))
      << ")\n";
  return result;
}

}  // namespace arview
