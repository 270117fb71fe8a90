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
  for (std::size_t i = 0; i < plan.tasks.size(); ++i) {
    const std::string clean =
        i < plan.task_outputs.size() ? "rm -rf -- " + ShellQuoted(plan.task_outputs[i].string()) + " && " : "";
    s += "  " + std::to_string(i) + ") " + clean + "exec " + ShellLine(plan.tasks[i]) + " ;;\n";
  }
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

// Every job submitted for one plan: the array, each retry, each final job.
class SubmittedJobs {
 public:
  SubmittedJobs(const SlurmJobPlan& plan, const SlurmOptions& options, int cpus_per_task)
      : plan_(plan), options_(options), cpus_(cpus_per_task) {
    WriteFileAtomically(ArrayScriptPath(), ArrayScript(plan_));
    WriteFileAtomically(FinalScriptPath(), FinalScript(plan_));
  }

  // The array's tasks `tasks` ("0-3", or one task's index for its retry, which appends to the
  // task's log); returns the job id (its tasks are "<id>_<task>").
  std::string SubmitTasks(const std::string& tasks, bool retry) {
    Command argv = Common(retry);
    argv.insert(argv.end(), {"--job-name", plan_.job_name, "--array", tasks, "--output",
                             (plan_.work_dir / "task_%a.log").string(), ArrayScriptPath().string()});
    return Submitted(SubmittedJobId(RunClient(argv, Log(), {}), retry ? "a retry of " + tasks : "the job array"));
  }

  // The final job after every job of `after` (none: at once).
  std::string SubmitFinal(const std::vector<std::string>& after, bool retry) {
    Command argv = Common(retry);
    argv.insert(argv.end(), {"--job-name", plan_.job_name + "-final", "--output", FinalLog(plan_).string()});
    if (!after.empty()) {
      std::string dependency = "afterok";
      for (const auto& id : after) dependency += ":" + id;
      argv.insert(argv.end(), {"--dependency", dependency, "--kill-on-invalid-dep=yes"});
    }
    argv.push_back(FinalScriptPath().string());
    return Submitted(SubmittedJobId(RunClient(argv, Log(), {}), plan_.final_name));
  }

  // Every job's state now, by id ("<array>_<task>", "<final>"); nothing when squeue fails.
  std::optional<std::map<std::string, std::string>> States(const CancellationToken& cancel) const {
    std::string ids;
    for (const auto& id : submitted_) ids += (ids.empty() ? "" : ",") + id;
    const Command argv{options_.squeue, "-h", "-r", "--states=all", "-j", ids, "-o", "%i|%T"};
    std::vector<std::string> lines;
    const ProcessResult r = RunProcess(argv, "/dev/null", [&](const std::string& line) { lines.push_back(line); }, cancel);
    if (!r.ok()) return std::nullopt;
    std::map<std::string, std::string> states;
    for (const auto& job : ParseSqueue(lines)) states[job.id] = job.state;
    return states;
  }

  // scancel of some jobs, or of every job submitted (their own token: the run's may be cancelled
  // already). Cancelling a job that ended does nothing.
  void Cancel(const std::vector<std::string>& ids) const {
    if (ids.empty()) return;
    Command argv{options_.scancel};
    argv.insert(argv.end(), ids.begin(), ids.end());
    try {
      RunProcess(argv, Log(), {});
    } catch (const Error&) {
      // scancel missing: sbatch worked, so it is not; nothing more can be done from here.
    }
  }
  void CancelAll() const { Cancel(submitted_); }

  fs::path Log() const { return plan_.work_dir / "slurm.log"; }

 private:
  fs::path ArrayScriptPath() const { return plan_.work_dir / "tasks.sbatch"; }
  fs::path FinalScriptPath() const { return plan_.work_dir / "final.sbatch"; }

  // --no-requeue: a job whose node died ends NODE_FAIL, and arview retries it (once), rather than
  // Slurm requeueing it without end. A retry appends to the first try's log.
  Command Common(bool retry) const {
    Command argv{options_.sbatch, "--parsable", "--no-requeue", "--chdir", plan_.work_dir.string(), "--cpus-per-task",
                 std::to_string(cpus_)};
    if (!options_.partition.empty()) argv.insert(argv.end(), {"--partition", options_.partition});
    if (options_.time_limit_minutes > 0) argv.push_back("--time=" + std::to_string(options_.time_limit_minutes));
    if (retry) argv.push_back("--open-mode=append");
    return argv;
  }

  std::string Submitted(std::string id) {
    submitted_.push_back(id);
    return id;
  }

  const SlurmJobPlan& plan_;
  const SlurmOptions& options_;
  int cpus_;
  std::vector<std::string> submitted_;
};

// Waits `wait`, returning early when cancelled.
void Sleep(std::chrono::milliseconds wait, const CancellationToken& cancel) {
  const auto until = Clock::now() + wait;
  while (Clock::now() < until && !cancel.IsCancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

// One job's try: its id and how it ended ("FAILED: <its last line>").
struct JobTry {
  std::string id;
  std::string ended;
};

// "leaf 1 (12 frames) failed on Slurm twice (job 70_1: FAILED: <last line>; before, job 68_1:
// NODE_FAIL); the other jobs were cancelled; its output is in <log>"
std::string Failure(const std::string& name, const std::vector<JobTry>& tries, const fs::path& log) {
  std::string text = name + " failed on Slurm" + (tries.size() == 2 ? " twice" : tries.size() > 2 ? " " + std::to_string(tries.size()) + " times" : "") +
                     " (job " + tries.back().id + ": " + tries.back().ended;
  for (std::size_t k = tries.size() - 1; k-- > 0;) text += "; before, job " + tries[k].id + ": " + tries[k].ended;
  return text + "); the other jobs were cancelled; its output is in " + log.string();
}

// How a job ended, for messages: its state and why (`why`, else the last line of its log).
std::string Ended(const std::string& state, const std::string& why, const fs::path& log) {
  const std::string said = why.empty() ? LastLine(log) : why;
  // Slurm's own last line then is "*** JOB ... CANCELLED ... DUE TO TIME LIMIT ***": say it plainly.
  if (state == "TIMEOUT") return state + ": ran past its time limit (--slurm-time-limit, or the partition's)";
  return state + (said.empty() ? "" : ": " + said);
}

// One plan's jobs followed to their end (RunSlurmJobs).
class JobFollower {
 public:
  JobFollower(const SlurmJobPlan& plan, const SlurmOptions& options, int cpus, const SlurmCallbacks& callbacks)
      : plan_(plan), callbacks_(callbacks), jobs_(plan, options, cpus), tasks_(plan.tasks.size()) {
    const std::string array = jobs_.SubmitTasks("0-" + std::to_string(plan.tasks.size() - 1), false);
    for (std::size_t i = 0; i < tasks_.size(); ++i) tasks_[i].tries.push_back({array + "_" + std::to_string(i), ""});
    if (!HasFinal()) return;
    try {
      final_.tries.push_back({jobs_.SubmitFinal({array}, false), ""});
    } catch (const Error&) {
      jobs_.CancelAll();
      throw;
    }
  }

  // One look at the jobs' states; true when the final job completed after every task.
  bool Step(const std::map<std::string, std::string>& states) {
    bool final_stale = false;
    for (std::size_t i = 0; i < tasks_.size(); ++i) final_stale |= StepTask(static_cast<int>(i), states);
    const bool tasks_done = std::all_of(tasks_.begin(), tasks_.end(), [](const Job& t) { return t.done; });
    if (!HasFinal()) return tasks_done;
    if (final_stale) {
      ResubmitFinal();
      return false;
    }
    const auto it = states.find(final_.tries.back().id);
    if (it == states.end()) return false;
    final_.state = it->second;
    if (SlurmStateFailed(it->second)) {
      const std::string said = LastLine(FinalLog(plan_));
      const bool hopeless = !plan_.final_failure_marker.empty() &&
                            said.find("printed '" + plan_.final_failure_marker + "'") != std::string::npos;
      final_.tries.back().ended = Ended(it->second, "", FinalLog(plan_));
      if (hopeless || static_cast<int>(final_.tries.size()) > plan_.retries)
        throw SlurmError(Failure(plan_.final_name, final_.tries, FinalLog(plan_)));
      Note(plan_.final_name, final_.tries.back());
      ResubmitFinal();
      return false;
    }
    return SlurmStateCompleted(it->second) && tasks_done;
  }

  void ReportProgress() {
    SlurmProgress p;
    p.total = static_cast<int>(tasks_.size()) + (HasFinal() ? 1 : 0);
    for (const Job& t : tasks_) Count(t.done ? "COMPLETED" : t.state, &p);
    if (HasFinal()) Count(final_.state, &p);
    if (p.queued == reported_.queued && p.running == reported_.running && p.done == reported_.done) return;
    reported_ = p;
    if (callbacks_.progress) callbacks_.progress(p);
  }

  std::optional<std::map<std::string, std::string>> States(const CancellationToken& cancel) const {
    return jobs_.States(cancel);
  }
  void CancelAll() const { jobs_.CancelAll(); }

 private:
  struct Job {
    std::vector<JobTry> tries;
    std::string state;  // the current try's, as squeue last said
    bool done = false;  // completed and accepted
  };

  bool HasFinal() const { return !plan_.final_commands.empty(); }

  static void Count(const std::string& state, SlurmProgress* p) {
    if (state == "PENDING" || state == "CONFIGURING" || state == "REQUEUED") ++p->queued;
    else if (state == "RUNNING" || state == "COMPLETING") ++p->running;
    else if (SlurmStateCompleted(state)) ++p->done;
  }

  // Task i's state; true when it was submitted again (the final job must then wait for the retry).
  bool StepTask(int i, const std::map<std::string, std::string>& states) {
    Job& task = tasks_[i];
    if (task.done) return false;
    const auto it = states.find(task.tries.back().id);
    if (it == states.end()) return false;  // not listed yet
    task.state = it->second;
    std::string why;
    if (SlurmStateCompleted(it->second)) {
      why = plan_.check_task ? plan_.check_task(i) : "";
      if (why.empty()) {
        task.done = true;
        return false;
      }
    } else if (!SlurmStateFailed(it->second)) {
      return false;
    }
    task.tries.back().ended = Ended(it->second, why, TaskLog(plan_, i));
    if (static_cast<int>(task.tries.size()) > plan_.retries)
      throw SlurmError(Failure(plan_.task_names[i], task.tries, TaskLog(plan_, i)));
    Note(plan_.task_names[i], task.tries.back());
    task.tries.push_back({jobs_.SubmitTasks(std::to_string(i), true) + "_" + std::to_string(i), ""});
    task.state = "PENDING";
    return true;
  }

  // The final job again, after the tasks not done yet (their current tries).
  void ResubmitFinal() {
    jobs_.Cancel({final_.tries.back().id});
    std::vector<std::string> after;
    for (const Job& t : tasks_)
      if (!t.done) after.push_back(t.tries.back().id);
    const bool failed = !final_.tries.back().ended.empty();
    if (failed) {
      final_.tries.push_back({jobs_.SubmitFinal(after, true), ""});
    } else {
      final_.tries.back().id = jobs_.SubmitFinal(after, true);  // not a try of its own: it never ran
    }
    final_.state = "PENDING";
  }

  void Note(const std::string& name, const JobTry& failed) const {
    if (callbacks_.note)
      callbacks_.note(name + " failed on Slurm (job " + failed.id + ": " + failed.ended + "); submitting it once more");
  }

  const SlurmJobPlan& plan_;
  const SlurmCallbacks& callbacks_;
  SubmittedJobs jobs_;
  std::vector<Job> tasks_;
  Job final_;
  SlurmProgress reported_{-1, -1, -1, 0};
};

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

std::string SlurmProgress::Describe() const {
  return std::to_string(queued) + " queued, " + std::to_string(running) + " running, " + std::to_string(done) + " of " +
         std::to_string(total) + " done";
}

void RunSlurmJobs(const SlurmJobPlan& plan, const SlurmOptions& options, int cpus_per_task,
                  const CancellationToken& cancel, const SlurmCallbacks& callbacks) {
  if (plan.tasks.empty()) throw SlurmError("no tasks to submit to Slurm");
  fs::create_directories(plan.work_dir);
  JobFollower jobs(plan, options, std::max(1, cpus_per_task), callbacks);
  auto answered = Clock::now();
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
      const bool finished = jobs.Step(*states);
      jobs.ReportProgress();
      if (finished) return;
      Sleep(options.poll, cancel);
    }
  } catch (const Error&) {
    jobs.CancelAll();
    throw;
  }
}

}  // namespace arview::mapping
