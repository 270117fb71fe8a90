// `arview eval`'s trajectories (issue 41): an estimate, a ground truth and an --align-with
// trajectory read by recordings::ReadTum and judged by EvaluateTrajectory in each alignment mode,
// then reported as text and JSON, as the command does. Besides a crash or an exception that is
// not an arview::Error, a report that is not a number is a finding: eval must refuse what it
// cannot judge ("an error, never a number", docs/recordings.md), not print an ATE of inf, a NaN
// RPE or a scale of 1e-17 (issue 41's findings, made by hand before this target).
//
// Input: one byte of options (bits 0-1: alignment none, se3, sim3, sim3; bit 2: fit the alignment
// on the third trajectory; bits 3-5: the RPE interval 1-8; bit 6: a tolerance of 0.5 s instead of
// 0.02 s), then the estimate, a line "=====", the ground truth, a line "=====", the --align-with
// trajectory.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

#include "base/error.h"
#include "fuzz/fuzz_support.h"
#include "recordings/accuracy.h"
#include "recordings/trajectory.h"

namespace {

using arview::recordings::AccuracyReport;

[[noreturn]] void Finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_eval: %s\n", what.c_str());
  std::abort();
}

void RequireNumber(double value, double at_most, const char* what) {
  if (!std::isfinite(value) || std::abs(value) > at_most) {
    Finding(std::string("the report's ") + what + " is " + std::to_string(value));
  }
}

void RequireSummary(const arview::Summary& s, const char* what) {
  for (const double v : {s.mean, s.median, s.rmse, s.min, s.max, s.p90, s.p95, s.p99}) RequireNumber(v, 1e300, what);
}

// What a report must be when eval prints one.
void RequireANumberReport(const AccuracyReport& r) {
  const auto& a = r.alignment;
  RequireNumber(a.scale, 1e300, "scale");
  if (!(a.scale > 0)) Finding("the report's scale is " + std::to_string(a.scale));
  if (!a.R.allFinite() || !a.t.allFinite()) Finding("the report's alignment is not finite");
  RequireSummary(r.ate, "ATE");
  RequireSummary(r.rotation_deg, "rotation error");
  RequireSummary(r.rpe_translation, "RPE translation");
  RequireSummary(r.rpe_rotation_deg, "RPE rotation");
  RequireNumber(r.coverage, 1, "coverage");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const unsigned options = data[0];
  std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  const auto& folder = arview::fuzz::ScratchFolder();
  const char* names[] = {"est.txt", "gt.txt", "align_with.txt"};
  for (const char* name : names) arview::fuzz::WriteBytes(folder / name, arview::fuzz::NextPart(rest, "\n=====\n"));
  arview::recordings::AccuracyOptions o;
  o.align = (options & 3) == 0 ? arview::recordings::AlignMode::kNone
            : (options & 3) == 1 ? arview::recordings::AlignMode::kSE3
                                 : arview::recordings::AlignMode::kSim3;
  o.rpe_delta = 1 + static_cast<int>((options >> 3) & 7);
  o.max_dt = (options & 64) ? 0.5 : 0.02;
  try {
    const auto estimate = arview::recordings::ReadTum(folder / names[0]);
    const auto groundtruth = arview::recordings::ReadTum(folder / names[1]);
    arview::recordings::Trajectory align_with;
    if ((options & 4) && o.align != arview::recordings::AlignMode::kNone) {
      align_with = arview::recordings::ReadTum(folder / names[2]);
      o.align_with = &align_with;
    }
    const AccuracyReport report = arview::recordings::EvaluateTrajectory(estimate, groundtruth, o);
    RequireANumberReport(report);
    (void)arview::recordings::ReportToText(report);
    (void)arview::recordings::ReportToJson(report);
  } catch (const arview::Error&) {
    // A refusal naming what it cannot judge: what eval should do.
  }
  return 0;
}
