// An in-process mutation driver for the fuzz targets, for builds without libFuzzer (the release
// and asan presets, gcc): it links with a target's LLVMFuzzerTestOneInput (and
// LLVMFuzzerInitialize, when the target has one), runs every seed once, then seeded random
// mutations of them for a fixed time. No coverage feedback (libFuzzer's `fuzz` preset has it):
// this is the short regression run that ctest does on every build (label `fuzz`,
// docs/reliability.md "Fuzzing in ctest").
//
//   fuzz_camera [options] [file...]
//     --seconds S        time budget, seeds included (default 20)
//     --runs N           stop after N executions (with --seed: the same inputs again)
//     --seed N           the mutations' random seed (default: from the clock; always printed)
//     --max-len N        inputs longer are cut (default 8192)
//     --timeout S        one input running longer is a finding (default 10)
//     --corpus DIR       every file in DIR is a seed (repeatable)
//     --data-seed REL    a real file from the shared data folder ($ARVIEW_DATA_DIR, else
//                        ../shared/data) as a seed; --head N keeps its first N lines and
//                        --prefix TEXT (\n for a new line) goes before it (both apply to the
//                        --data-seed before them). Missing: skipped, or a failure under
//                        ARVIEW_REQUIRE_DATA=1
//     --artifacts DIR    where an input that crashed, threw or hung is written (default .)
//   Files given without an option are run once each, nothing else (reproducing a finding).
//
// A finding (a signal such as SIGSEGV or SIGABRT, a sanitizer report, an exception escaping the
// target, an input running over --timeout) writes the input to <artifacts>/<kind>-<hash>,
// prints its path and the run's seed, and ends the process with a non-zero status.

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "base/hash.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int* argc, char*** argv);
// Present when the program is built with a sanitizer (the asan preset): called after its
// report, before the process exits.
extern "C" __attribute__((weak)) void __sanitizer_set_death_callback(void (*callback)(void));

// UBSan's defaults, read by its runtime before main. Under gcc, UBSan is a runtime of its own
// beside ASan's (libubsan, libasan): the death callback set above reaches only ASan's, and a
// UBSan report ended the process with exit(1) and no input kept (fuzz_driver_selftest's
// `signed` case found it). With abort_on_error it ends in abort(), whose SIGABRT handler below
// keeps the input. UBSAN_OPTIONS from the environment still overrides this.
extern "C" const char* __ubsan_default_options() { return "abort_on_error=1:print_stacktrace=1"; }

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// ---- The input being run, and writing it out from a signal handler --------------------------

// Set before each execution; read by the signal handlers, the sanitizer's death callback and the
// watchdog thread. The buffer is not touched while the target runs.
std::atomic<const std::uint8_t*> g_data{nullptr};
std::atomic<std::size_t> g_size{0};
std::atomic<std::uint64_t> g_execution{0};          // number of the execution running (1-based)
std::atomic<std::int64_t> g_started_ns{0};          // when it started (steady clock); 0 between runs
std::atomic<bool> g_reported{false};                // one report per process
char g_artifacts[4096] = ".";                       // the --artifacts folder
char g_seed_text[32] = "0";                         // the run's seed, for the report
char g_program[256] = "fuzz";
const std::array<int, 5> kFatalSignals{SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
std::array<struct sigaction, 5> g_previous{};

// Only async-signal-safe calls from here to the end of SaveCurrentInput.
void Print(const char* text) {
  size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t n = ::write(STDERR_FILENO, text, left);
    if (n <= 0) return;
    text += n;
    left -= static_cast<size_t>(n);
  }
}

void Append(char* out, size_t capacity, const char* text) {
  const size_t used = std::strlen(out);
  size_t i = 0;
  for (; text[i] && used + i + 1 < capacity; ++i) out[used + i] = text[i];
  out[used + i] = '\0';
}

void AppendNumber(char* out, size_t capacity, std::uint64_t value, int base) {
  char digits[24];
  int n = 0;
  do {
    const int d = static_cast<int>(value % static_cast<std::uint64_t>(base));
    digits[n++] = static_cast<char>(d < 10 ? '0' + d : 'a' + d - 10);
    value /= static_cast<std::uint64_t>(base);
  } while (value > 0);
  char text[24];
  for (int i = 0; i < n; ++i) text[i] = digits[n - 1 - i];
  text[n] = '\0';
  Append(out, capacity, text);
}

// Writes the input being run to <artifacts>/<kind>-<hash> and says so on stderr, once.
void SaveCurrentInput(const char* kind, const char* why) {
  if (g_reported.exchange(true)) return;
  const std::uint8_t* data = g_data.load();
  const size_t size = g_size.load();
  char path[4400] = "";
  Append(path, sizeof path, g_artifacts);
  Append(path, sizeof path, "/");
  Append(path, sizeof path, kind);
  Append(path, sizeof path, "-");
  AppendNumber(path, sizeof path, data ? arview::Fnv1aOf(data, size) : 0, 16);
  const int fd = ::open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  bool saved = fd >= 0;
  for (size_t done = 0; saved && done < size;) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n <= 0) saved = false;
    else done += static_cast<size_t>(n);
  }
  if (fd >= 0 && ::close(fd) != 0) saved = false;
  char line[6000] = "";
  Append(line, sizeof line, "\n");
  Append(line, sizeof line, g_program);
  Append(line, sizeof line, ": FINDING: ");
  Append(line, sizeof line, why);
  Append(line, sizeof line, " on execution ");
  AppendNumber(line, sizeof line, g_execution.load(), 10);
  Append(line, sizeof line, " (seed ");
  Append(line, sizeof line, g_seed_text);
  Append(line, sizeof line, ", input of ");
  AppendNumber(line, sizeof line, size, 10);
  Append(line, sizeof line, " bytes)\n");
  Append(line, sizeof line, g_program);
  Append(line, sizeof line, saved ? ": the input is saved as " : ": COULD NOT SAVE the input as ");
  Append(line, sizeof line, path);
  Append(line, sizeof line, "\n");
  Append(line, sizeof line, g_program);
  Append(line, sizeof line, ": reproduce it with: ");
  Append(line, sizeof line, g_program);
  Append(line, sizeof line, " ");
  Append(line, sizeof line, path);
  Append(line, sizeof line, "\n");
  Print(line);
}

void OnFatalSignal(int signal, siginfo_t* info, void*) {
  const char* name = signal == SIGSEGV ? "SIGSEGV" : signal == SIGBUS ? "SIGBUS" : signal == SIGFPE ? "SIGFPE"
                     : signal == SIGILL ? "SIGILL" : "SIGABRT";
  char why[64] = "signal ";
  Append(why, sizeof why, name);
  SaveCurrentInput("crash", why);
  // Hand the signal to whoever had it before (the sanitizer's handler, which prints its report,
  // or the default action): a fault repeats when the handler returns, a sent signal is re-raised.
  for (size_t i = 0; i < kFatalSignals.size(); ++i) {
    if (kFatalSignals[i] == signal) ::sigaction(signal, &g_previous[i], nullptr);
  }
  if (signal == SIGABRT || info == nullptr || info->si_code <= 0) ::raise(signal);
}

void OnSanitizerDeath() { SaveCurrentInput("crash", "a sanitizer report (above)"); }

void InstallCrashHandlers() {
  // The handlers must run on a stack of their own, or a stack overflow cannot be reported. A
  // sanitizer has already set one up for the main thread; keep it.
  stack_t current{};
  if (::sigaltstack(nullptr, &current) == 0 && (current.ss_flags & SS_DISABLE)) {
    static std::vector<char> stack(1 << 18);
    stack_t own{};
    own.ss_sp = stack.data();
    own.ss_size = stack.size();
    ::sigaltstack(&own, nullptr);
  }
  for (size_t i = 0; i < kFatalSignals.size(); ++i) {
    struct sigaction action {};
    action.sa_sigaction = OnFatalSignal;
    action.sa_flags = SA_SIGINFO | SA_ONSTACK | SA_NODEFER;
    sigemptyset(&action.sa_mask);
    ::sigaction(kFatalSignals[i], &action, &g_previous[i]);
  }
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(OnSanitizerDeath);
}

// ---- Seeds --------------------------------------------------------------------------------

struct Seed {
  std::string bytes;
  std::string source;
};

std::string ReadAll(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<fs::path> FilesIn(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());  // the same order every run: a seed reproduces a run
  return files;
}

fs::path DataFolder() {
  if (const char* env = std::getenv("ARVIEW_DATA_DIR"); env && *env) return env;
  return fs::path("..") / "shared" / "data";
}

std::string Unescape(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\\' && i + 1 < text.size() && text[i + 1] == 'n') {
      out += '\n';
      ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

std::string FirstLines(const std::string& text, long lines) {
  if (lines < 0) return text;
  size_t at = 0;
  for (long i = 0; i < lines && at != std::string::npos; ++i) {
    at = text.find('\n', at);
    if (at != std::string::npos) ++at;
  }
  return at == std::string::npos ? text : text.substr(0, at);
}

// ---- Mutations ----------------------------------------------------------------------------

class Mutator {
 public:
  Mutator(std::uint64_t seed, const std::vector<Seed>& seeds, size_t max_len) : rng_(seed), seeds_(seeds), max_len_(max_len) {}

  std::string Next() {
    std::string input = seeds_[Below(seeds_.size())].bytes;
    // Mostly one or two changes, sometimes a pile of them (as libFuzzer's mutation depth).
    const size_t count = Below(4) == 0 ? 1 + Below(16) : 1 + Below(2);
    for (size_t i = 0; i < count; ++i) MutateOnce(input);
    if (input.size() > max_len_) input.resize(max_len_);
    return input;
  }

 private:
  size_t Below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(rng_() % n); }
  char RandomByte() { return static_cast<char>(rng_() & 0xff); }
  const std::string& OtherSeed() { return seeds_[Below(seeds_.size())].bytes; }

  void MutateOnce(std::string& s) {
    switch (Below(12)) {
      case 0:  // flip a bit
        if (!s.empty()) s[Below(s.size())] ^= static_cast<char>(1 << Below(8));
        break;
      case 1:  // set a byte
        if (!s.empty()) s[Below(s.size())] = RandomByte();
        break;
      case 2: {  // insert bytes, random or one repeated
        const size_t n = 1 + Below(Below(2) ? 4 : 64);
        const char repeated = RandomByte();
        std::string bytes;
        for (size_t i = 0; i < n; ++i) bytes += Below(2) ? repeated : RandomByte();
        s.insert(Below(s.size() + 1), bytes);
        break;
      }
      case 3: {  // delete a range
        if (s.empty()) break;
        const size_t at = Below(s.size());
        s.erase(at, 1 + Below(std::min<size_t>(s.size() - at, Below(2) ? 4 : 256)));
        break;
      }
      case 4:  // cut the input short (a truncated file)
        s.resize(Below(s.size() + 1));
        break;
      case 5: {  // copy a chunk over another place
        if (s.size() < 2) break;
        const size_t from = Below(s.size()), to = Below(s.size());
        const size_t n = 1 + Below(std::min(s.size() - from, s.size() - to));
        const std::string chunk = s.substr(from, n);
        s.replace(to, n, chunk);
        break;
      }
      case 6: {  // duplicate a chunk (a repeated line, key or section)
        if (s.empty()) break;
        const size_t from = Below(s.size());
        const std::string chunk = s.substr(from, 1 + Below(std::min<size_t>(s.size() - from, 512)));
        s.insert(Below(s.size() + 1), chunk);
        break;
      }
      case 7: {  // splice: this input's head with another seed's tail, or a chunk of it inserted
        const std::string& other = OtherSeed();
        if (other.empty()) break;
        const size_t from = Below(other.size());
        if (Below(2)) {
          s = s.substr(0, Below(s.size() + 1)) + other.substr(from);
        } else {
          s.insert(Below(s.size() + 1), other.substr(from, 1 + Below(std::min<size_t>(other.size() - from, 512))));
        }
        break;
      }
      case 8:
      case 9:  // an interesting integer, binary, either byte order
        InterestingInteger(s);
        break;
      default:  // edit a number written in ASCII
        AsciiNumber(s);
        break;
    }
  }

  void InterestingInteger(std::string& s) {
    static constexpr std::uint64_t kValues[] = {0,          1,          2,          3,          7,
                                                8,          16,         31,         32,         63,
                                                64,         100,        127,        128,        255,
                                                256,        512,        1000,       1024,       4096,
                                                32767,      32768,      65535,      65536,      0x7fffffff,
                                                0x80000000, 0xffffffff, 0x100000000, 0x7fffffffffffffff,
                                                0x8000000000000000, ~std::uint64_t{0}, ~std::uint64_t{0} - 1};
    static constexpr size_t kWidths[] = {1, 2, 4, 8};
    const size_t width = kWidths[Below(4)];
    if (s.size() < width) return;
    std::uint64_t value = kValues[Below(std::size(kValues))];
    if (Below(4) == 0) value = ~value + 1;  // its negative
    const size_t at = Below(s.size() - width + 1);
    const bool big_endian = Below(2);
    for (size_t i = 0; i < width; ++i) {
      const size_t shift = 8 * (big_endian ? width - 1 - i : i);
      s[at + i] = static_cast<char>((value >> shift) & 0xff);
    }
  }

  void AsciiNumber(std::string& s) {
    static constexpr const char* kNumbers[] = {"0",   "-0",  "1",          "-1",       "2",          "255", "256",
                                               "65535", "65536", "2147483647", "2147483648", "-2147483649",
                                               "4294967296", "18446744073709551615", "18446744073709551616",
                                               "99999999999999999999999", "1e308", "-1e308", "1e-320", "1e400",
                                               "nan", "-nan", "inf", "-inf", "0x10", "1.5", "+1", "00", "", "-"};
    // Find a digit from a random place on; at the end, put the number at a random place.
    size_t at = Below(s.size() + 1);
    while (at < s.size() && !(s[at] >= '0' && s[at] <= '9')) ++at;
    if (at >= s.size()) {
      s.insert(Below(s.size() + 1), kNumbers[Below(std::size(kNumbers))]);
      return;
    }
    size_t end = at;
    while (end < s.size() && ((s[end] >= '0' && s[end] <= '9') || s[end] == '.' || s[end] == 'e' || s[end] == '-')) ++end;
    switch (Below(4)) {
      case 0:  // another digit
        s[at + Below(end - at)] = static_cast<char>('0' + Below(10));
        break;
      case 1:  // one more digit
        s.insert(at + Below(end - at + 1), 1, static_cast<char>('0' + Below(10)));
        break;
      default:  // the whole number replaced
        s.replace(at, end - at, kNumbers[Below(std::size(kNumbers))]);
        break;
    }
  }

  std::mt19937_64 rng_;
  const std::vector<Seed>& seeds_;
  size_t max_len_;
};

// ---- Running ------------------------------------------------------------------------------

std::int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// Runs one input as libFuzzer does: a heap buffer of exactly its size (a read past its end is a
// sanitizer report). An exception that escapes the target is a finding.
void RunOne(const std::string& input, std::uint64_t execution) {
  const std::unique_ptr<std::uint8_t[]> buffer(new std::uint8_t[input.size()]);
  std::memcpy(buffer.get(), input.data(), input.size());
  g_data = buffer.get();
  g_size = input.size();
  g_execution = execution;
  g_started_ns = NowNs();
  try {
    LLVMFuzzerTestOneInput(buffer.get(), input.size());
  } catch (const std::exception& e) {
    const std::string why = std::string("an exception escaped the target: ") + e.what();
    SaveCurrentInput("exception", why.substr(0, 1000).c_str());
    std::exit(1);
  } catch (...) {
    SaveCurrentInput("exception", "an exception of an unknown type escaped the target");
    std::exit(1);
  }
  g_started_ns = 0;
}

// Ends the process when one input runs longer than `timeout` (a hang; libFuzzer's -timeout).
void StartWatchdog(double timeout) {
  std::thread([timeout] {
    const auto limit = static_cast<std::int64_t>(timeout * 1e9);
    for (;;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      const std::int64_t started = g_started_ns.load();
      if (started != 0 && NowNs() - started > limit) {
        const std::string why = "an input ran over " + std::to_string(timeout) + " s";
        SaveCurrentInput("timeout", why.c_str());
        std::_Exit(1);
      }
    }
  }).detach();
}

struct Options {
  double seconds = 20;
  std::uint64_t runs = 0;  // 0: no limit
  bool seed_given = false;
  std::uint64_t seed = 0;
  size_t max_len = 8192;
  double timeout = 10;
  std::vector<fs::path> corpora;
  struct DataSeed {
    std::string relative;
    long head = -1;
    std::string prefix;
  };
  std::vector<DataSeed> data_seeds;
  fs::path artifacts = ".";
  std::vector<fs::path> files;
};

Options ParseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--seconds") o.seconds = std::stod(value());
    else if (arg == "--runs") o.runs = std::stoull(value());
    else if (arg == "--seed") o.seed = std::stoull(value()), o.seed_given = true;
    else if (arg == "--max-len") o.max_len = std::stoul(value());
    else if (arg == "--timeout") o.timeout = std::stod(value());
    else if (arg == "--corpus") o.corpora.push_back(value());
    else if (arg == "--data-seed") o.data_seeds.push_back({value(), -1, ""});
    else if (arg == "--head" || arg == "--prefix") {
      if (o.data_seeds.empty()) throw std::runtime_error(arg + " must follow a --data-seed");
      if (arg == "--head") o.data_seeds.back().head = std::stol(value());
      else o.data_seeds.back().prefix = Unescape(value());
    } else if (arg == "--artifacts") o.artifacts = value();
    else if (arg.rfind("--", 0) == 0) throw std::runtime_error("unknown option " + arg);
    else o.files.push_back(arg);
  }
  if (!(o.seconds > 0) || !(o.timeout > 0) || o.max_len == 0) throw std::runtime_error("--seconds, --timeout and --max-len must be positive");
  return o;
}

// Seeds the target writes itself (valid files from our writers): LLVMFuzzerInitialize writes
// them into the folder named by ARVIEW_FUZZ_WRITE_SEED, as scripts/fuzz.sh has it do.
std::vector<Seed> SeedsWrittenByTheTarget(int* argc, char*** argv) {
  if (!LLVMFuzzerInitialize) return {};
  char folder_template[] = "/tmp/arview-fuzz-seeds-XXXXXX";
  const char* folder = ::mkdtemp(folder_template);
  if (!folder) throw std::runtime_error("cannot make a temporary folder for the target's seeds");
  ::setenv("ARVIEW_FUZZ_WRITE_SEED", folder, 1);
  LLVMFuzzerInitialize(argc, argv);
  ::unsetenv("ARVIEW_FUZZ_WRITE_SEED");
  std::vector<Seed> seeds;
  for (const fs::path& file : FilesIn(folder)) seeds.push_back({ReadAll(file), "written by the target: " + file.filename().string()});
  fs::remove_all(folder);
  return seeds;
}

int Main(int argc, char** argv) {
  const Options o = ParseOptions(argc, argv);
  std::snprintf(g_program, sizeof g_program, "%s", fs::path(argv[0]).filename().c_str());
  const std::string program = g_program;
  fs::create_directories(o.artifacts);
  std::snprintf(g_artifacts, sizeof g_artifacts, "%s", fs::absolute(o.artifacts).c_str());
  InstallCrashHandlers();
  StartWatchdog(o.timeout);

  if (!o.files.empty()) {  // reproduce: run the files given, once each
    if (LLVMFuzzerInitialize) LLVMFuzzerInitialize(&argc, &argv);
    std::uint64_t execution = 0;
    for (const fs::path& file : o.files) {
      std::printf("%s: running %s\n", program.c_str(), file.c_str());
      std::fflush(stdout);
      RunOne(ReadAll(file), ++execution);
    }
    std::printf("%s: %zu inputs ran without a finding\n", program.c_str(), o.files.size());
    return 0;
  }

  std::vector<Seed> seeds;
  size_t from_corpus = 0, from_data = 0;
  for (const fs::path& folder : o.corpora) {
    if (!fs::is_directory(folder)) throw std::runtime_error(folder.string() + ": not a folder of seeds");
    for (const fs::path& file : FilesIn(folder)) seeds.push_back({ReadAll(file), file.string()}), ++from_corpus;
  }
  std::vector<Seed> written = SeedsWrittenByTheTarget(&argc, &argv);
  const size_t from_target = written.size();
  seeds.insert(seeds.end(), written.begin(), written.end());
  const char* required = std::getenv("ARVIEW_REQUIRE_DATA");
  for (const auto& data_seed : o.data_seeds) {
    const fs::path file = DataFolder() / data_seed.relative;
    if (!fs::is_regular_file(file)) {
      if (required && std::string(required) == "1") {
        throw std::runtime_error("missing seed from the shared data: " + file.string() + " (ARVIEW_REQUIRE_DATA=1)");
      }
      std::printf("%s: seed %s skipped: not found (shared data)\n", program.c_str(), file.c_str());
      continue;
    }
    seeds.push_back({data_seed.prefix + FirstLines(ReadAll(file), data_seed.head), file.string()});
    ++from_data;
  }
  if (seeds.empty()) seeds.push_back({"", "the empty input"});
  for (Seed& seed : seeds) {
    if (seed.bytes.size() > o.max_len) seed.bytes.resize(o.max_len);
  }

  std::uint64_t seed = o.seed;
  if (!o.seed_given) {
    std::random_device device;
    seed = ((std::uint64_t{device()} << 32) | device()) ^ static_cast<std::uint64_t>(NowNs());
  }
  std::snprintf(g_seed_text, sizeof g_seed_text, "%llu", static_cast<unsigned long long>(seed));
  std::printf("%s: %zu seeds (%zu from the corpus folders, %zu written by the target, %zu from the shared data); "
              "seed %llu, %.0f s, inputs up to %zu bytes\n",
              program.c_str(), seeds.size(), from_corpus, from_target, from_data, static_cast<unsigned long long>(seed),
              o.seconds, o.max_len);
  std::fflush(stdout);

  const auto start = Clock::now();
  const auto deadline = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.seconds));
  std::uint64_t executions = 0;
  for (const Seed& s : seeds) {  // every seed once, whatever the budget
    if (o.runs && executions >= o.runs) break;
    RunOne(s.bytes, ++executions);
  }
  const std::uint64_t seed_executions = executions;
  Mutator mutator(seed, seeds, o.max_len);
  while ((!o.runs || executions < o.runs) && Clock::now() < deadline) RunOne(mutator.Next(), ++executions);
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("%s: %llu executions (%llu seeds, %llu mutated) in %.1f s, %.0f a second; seed %llu; "
              "no crash, sanitizer report, escaped exception or input over %.0f s\n",
              program.c_str(), static_cast<unsigned long long>(executions), static_cast<unsigned long long>(seed_executions),
              static_cast<unsigned long long>(executions - seed_executions), elapsed, executions / elapsed,
              static_cast<unsigned long long>(seed), o.timeout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 2;
  }
}
