#pragma once
// stats.json and the console summary of a pipeline run.

#include <string>

#include <nlohmann/json.hpp>

#include "app/pipeline/ar_pipeline.h"
#include "render/offscreen.h"

namespace arview::app {

struct GazeSummary {
  size_t frames = 0;
  double median_deg = 0;
  double max_deg = 0;
  size_t within_20_deg = 0;
};

GazeSummary SummarizeGaze(const PipelineReport& report);
// The timing object of stats.json: {count, median_ms, p95_ms, mean_ms, max_ms}.
nlohmann::ordered_json TimingJson(const TimingSummary& summary);
// `gl`: what rendered (stats.json's "gl": backend, device, vendor, renderer, version, software).
std::string PipelineReportJson(const PipelineReport& report, const std::string& gl_description,
                               const render::RendererInfo& gl = {});
std::string PipelineReportText(const PipelineReport& report);

}  // namespace arview::app
