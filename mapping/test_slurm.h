#pragma once
// For the tests labelled `slurm` (mapping/leaf_mapping_test.cpp, mapping/job_stages_test.cpp):
// whether the cluster of scripts/slurm-local.sh answers, the skip when it does not, and the jobs
// still queued after a run.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "base/process.h"
#include "tests/support/test_data.h"

namespace arview::mapping {

// Whether the cluster of scripts/slurm-local.sh (or another that SLURM_CONF names) answers.
inline bool SlurmAnswers() {
  const std::filesystem::path log = std::filesystem::temp_directory_path() / ("arview_sinfo_" + std::to_string(::getpid()) + ".log");
  bool idle = false;
  try {
    const ProcessResult r = RunProcess({"sinfo", "-h", "-o", "%T"}, log, [&](const std::string& line) {
      idle = idle || line.find("idle") != std::string::npos || line.find("mixed") != std::string::npos;
    });
    idle = idle && r.ok();
  } catch (const Error&) {
    idle = false;  // sinfo not installed
  }
  std::filesystem::remove(log);
  return idle;
}

#define ARVIEW_REQUIRE_SLURM()                                                                          \
  do {                                                                                                  \
    if (!SlurmAnswers()) {                                                                              \
      const char* why = "needs a running Slurm cluster: bash scripts/slurm-local.sh start, then "      \
                        "export SLURM_CONF=$(bash scripts/slurm-local.sh conf) (scripts/test.sh does both)"; \
      if (testing::DataRequired()) FAIL() << why << "; ARVIEW_REQUIRE_DATA=1 makes this a failure";   \
      GTEST_SKIP() << why;                                                                              \
    }                                                                                                   \
  } while (0)

// The jobs of `name` still pending or running.
inline std::vector<std::string> QueuedJobs(const std::string& name) {
  std::vector<std::string> lines;
  const std::filesystem::path log = std::filesystem::temp_directory_path() / ("arview_squeue_" + std::to_string(::getpid()) + ".log");
  RunProcess({"squeue", "-h", "-t", "PENDING,RUNNING,COMPLETING", "-n", name + "," + name + "-final", "-o", "%i %T"}, log,
             [&](const std::string& line) { lines.push_back(line); });
  std::filesystem::remove(log);
  return lines;
}

// The jobs of `name` still queued once scancel had up to 10 s to take them off.
inline std::vector<std::string> QueuedAfterCancelling(const std::string& name) {
  std::vector<std::string> queued = QueuedJobs(name);
  for (int i = 0; i < 50 && !queued.empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    queued = QueuedJobs(name);
  }
  return queued;
}

}  // namespace arview::mapping
