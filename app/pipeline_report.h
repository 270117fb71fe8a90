#pragma once
// stats.json and the console summary of a pipeline run.

#include <string>

#include "app/ar_pipeline.h"

namespace arview::app {

struct GazeSummary {
  size_t frames = 0;
  double median_deg = 0;
  double max_deg = 0;
  size_t within_20_deg = 0;
};

GazeSummary SummarizeGaze(const PipelineReport& report);
std::string PipelineReportJson(const PipelineReport& report, const std::string& gl_description);
std::string PipelineReportText(const PipelineReport& report);

}  // namespace arview::app
