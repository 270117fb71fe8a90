#include "mapping/slurm_engine.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <thread>

#include "base/atomic_file.h"
#include "base/process.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

std::string ArrayScript(const SlurmJobPlan& plan) {
  std::string s = "#!/bin/bash\n# " + plan.job_name + ": one task per line of the case, written by arview map.\n";
  s += "case \"${SLURM_ARRAY_TASK_ID:-}\" in\n";
  for (std::size_t i = 0; i < plan.tasks.size(); ++i) s += "  " + std::to_string(i) + ") exec " + ShellLine(plan.tasks[i]) + " ;;\n";
  s += "esac\necho \"arview: no task '${SLURM_ARRAY_TASK_ID:-}' in this job array\" >&2\nexit 2\n";
  return s;
}

// Each command in turn; the first that fails (or prints the failure marker) ends the job failed.
std::string FinalScript(const SlurmJobPlan& plan) {
  std::string s = "#!/bin/bash\n# " + plan.final_name + ", written by arview map.\nset -uo pipefail\n";
  s += "marker=" + ShellQuoted(plan.final_failure_marker) + "\n";
  s += R"SH(run() {
  local out
  out="$(mktemp)"
  "$@" 2>&1 | tee "$out"
  local rc=${PIPESTATUS[0]}
  local what="$(basename "$1") ${2:-}"
  if [ "$rc" -ne 0 ]; then echo "arview: $what exited with code $rc"; rm -f "$out"; exit 1; fi
  if [ -n "$marker" ] && grep -qF -- "$marker" "$out"; then echo "arview: $what printed '$marker'"; rm -f "$out"; exit 3; fi
  rm -f "$out"
}
)SH";
  for (const auto& command : plan.final_commands) s += "run " + ShellLine(command) + "\n";
  return s;
}

// The last non-empty line of a log (empty when none or unreadable).
std::string LastLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last;
}

// Runs a Slurm client; its output lines, or SlurmError naming it and what it printed last.
std::vector<std::string> RunClient(const Command& argv, const fs::path& log, const CancellationToken& cancel) {
  std::vector<std::string> lines;
  const ProcessResult r = RunProcess(argv, log, [&](const std::string& line) { lines.push_back(line); }, cancel);
  if (!r.ok()) {
    const std::string said = r.tail.empty() ? std::string("no output") : r.tail.back();
    throw SlurmError(argv.front() + " " + (r.signaled ? "was killed by signal " + std::to_string(r.signal)
                                                      : "exited with code " + std::to_string(r.exit_code)) +
                     ": " + said);
  }
  return lines;
}

std::string SubmittedJobId(const std::vector<std::string>& lines, const std::string& what) {
  // --parsable prints "<id>" or "<id>;<cluster>".
  const std::string last = lines.empty() ? "" : lines.back();
  const std::string id = last.substr(0, last.find(';'));
  if (id.empty() || !std::all_of(id.begin(), id.end(), [](char c) { return c >= '0' && c <= '9'; }))
    throw SlurmError("sbatch did not give a job id for " + what + " (it printed '" + last + "')");
  return id;
}

class SubmittedJobs {
 public:
  SubmittedJobs(const SlurmJobPlan& plan, const SlurmOptions& options) : plan_(plan), options_(options) {}

  void Submit(int cpus_per_task) {
    const fs::path array_script = plan_.work_dir / "tasks.sbatch", final_script = plan_.work_dir / "final.sbatch";
    WriteFileAtomically(array_script, ArrayScript(plan_));
    WriteFileAtomically(final_script, FinalScript(plan_));
    Command common{options_.sbatch, "--parsable", "--chdir", plan_.work_dir.string(), "--cpus-per-task",
                   std::to_string(cpus_per_task)};
    if (!options_.partition.empty()) common.insert(common.end(), {"--partition", options_.partition});
    Command array = common;
    array.insert(array.end(), {"--job-name", plan_.job_name, "--array",
                               "0-" + std::to_string(plan_.tasks.size() - 1), "--output",
                               (plan_.work_dir / "task_%a.log").string(), array_script.string()});
    array_id_ = SubmittedJobId(RunClient(array, Log(), {}), "the job array");
    Command last = common;
    last.insert(last.end(), {"--job-name", plan_.job_name + "-final", "--dependency", "afterok:" + array_id_,
                             "--kill-on-invalid-dep=yes", "--output", FinalLog(plan_).string(), final_script.string()});
    try {
      final_id_ = SubmittedJobId(RunClient(last, Log(), {}), plan_.final_name);
    } catch (const Error&) {
      Cancel();
      throw;
    }
  }

  // Every job's state now, by id ("<array>_<task>", "<final>"); nothing when squeue fails.
  std::optional<std::map<std::string, std::string>> States(const CancellationToken& cancel) const {
    const Command argv{options_.squeue, "-h", "-r", "--states=all", "-j", array_id_ + "," + final_id_, "-o", "%i|%T"};
    std::vector<std::string> lines;
    const ProcessResult r = RunProcess(argv, "/dev/null", [&](const std::string& line) { lines.push_back(line); }, cancel);
    if (!r.ok()) return std::nullopt;
    std::map<std::string, std::string> states;
    for (const auto& job : ParseSqueue(lines)) states[job.id] = job.state;
    return states;
  }

  // scancel of every job (their own token: the run's may be cancelled already).
  void Cancel() const {
    Command argv{options_.scancel, array_id_};
    if (!final_id_.empty()) argv.push_back(final_id_);
    try {
      RunProcess(argv, Log(), {});
    } catch (const Error&) {
      // scancel missing: sbatch worked, so it is not; nothing more can be done from here.
    }
  }

  std::string TaskId(int task) const { return array_id_ + "_" + std::to_string(task); }
  const std::string& FinalId() const { return final_id_; }
  fs::path Log() const { return plan_.work_dir / "slurm.log"; }

 private:
  const SlurmJobPlan& plan_;
  const SlurmOptions& options_;
  std::string array_id_, final_id_;
};

// Waits `wait`, returning early when cancelled.
void Sleep(std::chrono::milliseconds wait, const CancellationToken& cancel) {
  const auto until = Clock::now() + wait;
  while (Clock::now() < until && !cancel.IsCancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

std::string Failure(const std::string& name, const std::string& id, const std::string& state, const fs::path& log) {
  const std::string said = LastLine(log);
  return name + " failed on Slurm (job " + id + ": " + state + ")" + (said.empty() ? "" : ": " + said) +
         "; the other jobs were cancelled; its output is in " + log.string();
}

}  // namespace

fs::path TaskLog(const SlurmJobPlan& plan, int task) { return plan.work_dir / ("task_" + std::to_string(task) + ".log"); }
fs::path FinalLog(const SlurmJobPlan& plan) { return plan.work_dir / "final.log"; }

std::string ShellQuoted(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string ShellLine(const Command& command) {
  std::string line;
  for (const auto& word : command) line += (line.empty() ? "" : " ") + ShellQuoted(word);
  return line;
}

std::vector<SlurmJobState> ParseSqueue(const std::vector<std::string>& lines) {
  std::vector<SlurmJobState> jobs;
  for (const auto& line : lines) {
    const auto bar = line.find('|');
    if (bar == std::string::npos || bar == 0) continue;
    std::string state = line.substr(bar + 1);
    while (!state.empty() && (state.back() == ' ' || state.back() == '\r')) state.pop_back();
    jobs.push_back({line.substr(0, bar), state});
  }
  return jobs;
}

bool SlurmStateFailed(const std::string& state) {
  static const char* const kFailed[] = {"FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY",
                                        "BOOT_FAIL", "DEADLINE", "PREEMPTED", "REVOKED", "SPECIAL_EXIT"};
  return std::any_of(std::begin(kFailed), std::end(kFailed), [&](const char* s) { return state == s; });
}

bool SlurmStateCompleted(const std::string& state) { return state == "COMPLETED"; }

void RunSlurmJobs(const SlurmJobPlan& plan, const SlurmOptions& options, int cpus_per_task,
                  const CancellationToken& cancel, const std::function<void(int done, int total)>& progress) {
  if (plan.tasks.empty()) throw SlurmError("no tasks to submit to Slurm");
  fs::create_directories(plan.work_dir);
  SubmittedJobs jobs(plan, options);
  jobs.Submit(std::max(1, cpus_per_task));
  const int total = static_cast<int>(plan.tasks.size()) + 1;
  auto answered = Clock::now();
  int reported = -1;
  try {
    for (;;) {
      cancel.ThrowIfCancelled("the Slurm jobs were cancelled");
      const auto states = jobs.States(cancel);
      if (!states) {
        if (Clock::now() - answered > options.unanswered_limit) {
          throw SlurmError("Slurm did not answer (" + options.squeue + " failed for " +
                           std::to_string(options.unanswered_limit.count()) + " s); the jobs were cancelled");
        }
        Sleep(options.poll, cancel);
        continue;
      }
      answered = Clock::now();
      int done = 0;
      for (std::size_t i = 0; i < plan.tasks.size(); ++i) {
        const auto it = states->find(jobs.TaskId(static_cast<int>(i)));
        if (it == states->end()) continue;
        if (SlurmStateFailed(it->second)) {
          throw SlurmError(Failure(plan.task_names[i], it->first, it->second, TaskLog(plan, static_cast<int>(i))));
        }
        done += SlurmStateCompleted(it->second);
      }
      const auto last = states->find(jobs.FinalId());
      if (last != states->end() && SlurmStateFailed(last->second)) {
        throw SlurmError(Failure(plan.final_name, last->first, last->second, FinalLog(plan)));
      }
      const bool finished = last != states->end() && SlurmStateCompleted(last->second);
      done += finished;
      if (done != reported && progress) progress(done, total);
      reported = done;
      if (finished) return;
      Sleep(options.poll, cancel);
    }
  } catch (const Error&) {
    jobs.Cancel();
    throw;
  }
}

}  // namespace arview::mapping
