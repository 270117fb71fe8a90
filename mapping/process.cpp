#include "mapping/process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <sstream>
#include <thread>

extern char** environ;

namespace arview::mapping {

namespace {

volatile sig_atomic_t g_interrupted = 0;

extern "C" void OnInterrupt(int) { g_interrupted = 1; }

struct sigaction g_old_int;
struct sigaction g_old_term;

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

void StopChildGroup(pid_t pid) {
  ::kill(-pid, SIGTERM);
  for (int i = 0; i < 40; ++i) {  // up to 2 s to exit cleanly, then SIGKILL
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::kill(-pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

std::string Joined(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_interrupted = 0;
  struct sigaction sa {};
  sa.sa_handler = OnInterrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking poll() returns at once
  ::sigaction(SIGINT, &sa, &g_old_int);
  ::sigaction(SIGTERM, &sa, &g_old_term);
}

InterruptGuard::~InterruptGuard() {
  ::sigaction(SIGINT, &g_old_int, nullptr);
  ::sigaction(SIGTERM, &g_old_term, nullptr);
  g_interrupted = 0;  // an interruption belongs to the guard's scope, not to later runs
}

bool InterruptGuard::Interrupted() { return g_interrupted != 0; }

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
                         const std::function<void(const std::string&)>& on_line, std::size_t tail_lines) {
  if (argv.empty()) throw ProcessError("RunProcess: empty command");
  const std::string exe = FindExecutable(argv[0]);
  if (exe.empty()) throw ProcessError("'" + argv[0] + "' not found on PATH");

  std::ofstream log(log_path, std::ios::app);
  if (!log) throw ProcessError(log_path.string() + ": cannot open the log file for writing");
  log << "$ " << Joined(argv) << "\n";

  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw ProcessError(std::string("pipe: ") + std::strerror(errno));
  Fd read_end{pipe_fds[0]};
  Fd write_end{pipe_fds[1]};

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, write_end.fd, 1);
  posix_spawn_file_actions_adddup2(&actions, write_end.fd, 2);

  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigset_t empty_mask;
  sigemptyset(&empty_mask);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setsigmask(&attr, &empty_mask);
  // Its own process group: the terminal's Ctrl-C reaches only us, and we stop the whole group.
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);

  std::vector<char*> cargv;
  for (const auto& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawn(&pid, exe.c_str(), &actions, &attr, cargv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw ProcessError("cannot start '" + exe + "': " + std::strerror(rc));
  write_end.Close();

  ProcessResult result;
  std::deque<std::string> tail;
  LineSplitter splitter;
  auto emit = [&](const std::string& line) {
    log << line << "\n";
    tail.push_back(line);
    if (tail.size() > tail_lines) tail.pop_front();
    if (on_line) on_line(line);
  };
  char buffer[4096];
  for (;;) {
    if (InterruptGuard::Interrupted()) {
      StopChildGroup(pid);
      log << "(interrupted: stopped by the user)\n";
      throw InterruptedError("interrupted: stopped " + argv[0] + " " + (argv.size() > 1 ? argv[1] : ""));
    }
    pollfd p{read_end.fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, 200);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    const ssize_t n = ::read(read_end.fd, buffer, sizeof buffer);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) break;  // EOF: the child closed its output (normally: exited)
    try {
      splitter.Feed(buffer, static_cast<size_t>(n), emit);
    } catch (...) {
      StopChildGroup(pid);
      throw;
    }
  }
  splitter.Flush(emit);

  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    if (InterruptGuard::Interrupted()) {
      StopChildGroup(pid);
      throw InterruptedError("interrupted: stopped " + argv[0]);
    }
  }
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

}  // namespace arview::mapping
