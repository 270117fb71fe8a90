#pragma once
// Running `arview map`'s parallel stages on a Slurm cluster (`--engine slurm`,
// docs/mapping.md, "A venue in leaves"): one job array whose tasks are independent commands (each
// leaf's COLMAP mapper), then one job that runs after all of them succeeded (afterok: the merge),
// submitted with sbatch and followed with squeue until they end. The job scripts and logs live in
// a work folder every node must see (the map folder on a shared filesystem).
//
// A task or the final job that fails (its command failed, its node died, it timed out), or a task
// whose result `check_task` refuses, is submitted once more (`retries`): a node that died takes
// its job with it, and the job on another node (or the same one back) usually succeeds. The final
// job is resubmitted with the retried task in its dependency. A job that fails again, or a final
// job that printed the failure marker (a merge that cannot succeed on a second try), cancels
// every other job (scancel: no job is left queued on a dependency that can never be met) and is
// one SlurmError naming it, its job id, its state and the last line it printed. A cancelled token
// (Ctrl-C) cancels the jobs the same way. Jobs are submitted with --no-requeue: the retry is
// arview's, once, not Slurm's requeue without end.
#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "base/cancellation.h"
#include "map/map.h"

namespace arview::mapping {

struct SlurmError : map::MapError {
  using map::MapError::MapError;
};

struct SlurmOptions {
  std::string sbatch = "sbatch", squeue = "squeue", scancel = "scancel";
  std::string partition;  // --slurm-partition; empty: the cluster's default
  int cpus_per_task = 0;  // --slurm-cpus; 0: the command's --threads (1 when --threads is -1)
  // --slurm-time-limit: each job's wall-time limit in minutes (sbatch --time); 0: the partition's
  // default. A job that runs past it (a COLMAP that hangs: feature_extractor was once seen
  // deadlocked after its last image) ends TIMEOUT and is submitted once more like a failed one,
  // instead of holding its node until someone cancels it.
  int time_limit_minutes = 0;
  std::chrono::milliseconds poll{1000};
  // squeue failing (slurmctld down, unreachable) for this long fails the run.
  std::chrono::seconds unanswered_limit{60};
};

using Command = std::vector<std::string>;

// The job array and the job after it.
struct SlurmJobPlan {
  std::filesystem::path work_dir;     // job scripts and logs (created)
  std::string job_name = "arview";
  std::vector<Command> tasks;         // array task i runs tasks[i]
  std::vector<std::string> task_names;  // for messages: "leaf 2 (12 images)"
  // Per task (or none): a folder removed before the task's command runs, so that a retry never
  // finds what a try on a node that died half wrote.
  std::vector<std::filesystem::path> task_outputs;
  std::vector<Command> final_commands;  // run one after another by the job after the array (none: no such job)
  std::string final_name = "the final job";
  // A line that, printed by a final command, fails the job (COLMAP's model_merger exits 0 when
  // it cannot merge and says "=> Merge failed"), and is not retried. Empty: none.
  std::string final_failure_marker;
  // Times a failed job (task or final) is submitted again.
  int retries = 1;
  // Called once for each task that COMPLETED: why its result cannot be used (a leaf's model
  // missing or damaged), or empty when it can. A refused task fails as if its job had.
  std::function<std::string(int task)> check_task;
};

// Where the jobs stand, each time it changes: tasks queued (PENDING), running (RUNNING,
// COMPLETING), done (COMPLETED and accepted), and whether the final job is done; `total` counts
// the tasks and the final job.
struct SlurmProgress {
  int queued = 0, running = 0, done = 0, total = 0;
  std::string Describe() const;  // "2 queued, 1 running, 0 of 4 done"
};

struct SlurmCallbacks {
  std::function<void(const SlurmProgress&)> progress;
  std::function<void(const std::string&)> note;  // a job retried, and why
};

// Where the job of `plan` writes its output: task i's log, the final job's log (a retry appends
// to the same file).
std::filesystem::path TaskLog(const SlurmJobPlan& plan, int task);
std::filesystem::path FinalLog(const SlurmJobPlan& plan);

// Submits the plan and waits until every job ended. Throws SlurmError (a job failed twice,
// sbatch refused, squeue stopped answering), CancelledError (the jobs cancelled first),
// ProcessError (sbatch not found).
void RunSlurmJobs(const SlurmJobPlan& plan, const SlurmOptions& options, int cpus_per_task,
                  const CancellationToken& cancel, const SlurmCallbacks& callbacks = {});

// A word quoted for bash ('...' with ' as '\''); a command line of such words.
std::string ShellQuoted(const std::string& word);
std::string ShellLine(const Command& command);

// Parses squeue's "-h -r -o %i|%T" lines: job id (array tasks as <job>_<task>) and state.
struct SlurmJobState {
  std::string id;
  std::string state;  // PENDING, RUNNING, COMPLETED, FAILED, CANCELLED, ...
};
std::vector<SlurmJobState> ParseSqueue(const std::vector<std::string>& lines);
// Whether a state is final and a failure (FAILED, CANCELLED, TIMEOUT, NODE_FAIL, OUT_OF_MEMORY,
// BOOT_FAIL, DEADLINE, PREEMPTED), final and a success (COMPLETED).
bool SlurmStateFailed(const std::string& state);
bool SlurmStateCompleted(const std::string& state);

}  // namespace arview::mapping
