// bench_speech: what the speech thread and the frame path pay (docs/speech.md, "Figures").
//   build/release/speech/bench_speech
// Synthesis: one typical line with each voice; the counter real_time_fraction is the wall time
// of a synthesis over the seconds of audio it makes (issue 53's target: at most 0.05).
// Sampling: one VisemeTrack::Sample of that line's curves, at times spread over the line.
#include <benchmark/benchmark.h>

#include "speech/markup.h"
#include "speech/visemes.h"

namespace arview::speech {
namespace {

constexpr const char* kTypicalLine = "Hello! I am standing right here in your room; come closer and I will show you around.";

void BM_Synthesize(benchmark::State& state) {
  const Synthesizer synthesizer(static_cast<Voice>(state.range(0)));
  double audio_seconds = 0;
  for (auto _ : state) {
    const SpokenLine line = synthesizer.Synthesize(kTypicalLine);
    audio_seconds += line.DurationSeconds();
    benchmark::DoNotOptimize(line.samples.data());
  }
  state.SetLabel(ToString(synthesizer.voice()));
  // Wall seconds per second of audio (UseRealTime: the synthesis is single-threaded).
  state.counters["real_time_fraction"] =
      benchmark::Counter(audio_seconds, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Synthesize)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SampleVisemes(benchmark::State& state) {
  const SpokenLine line = Synthesizer(Voice::kSlt).Synthesize(kTypicalLine);
  const VisemeTrack track(line.phones);
  VisemeWeights weights;
  const double duration = line.DurationSeconds();
  double t = 0;
  for (auto _ : state) {
    track.Sample(t, weights);
    benchmark::DoNotOptimize(weights.data());
    t += 0.0137;  // not a divisor of a phone's length: the times fall all over the curves
    if (t > duration) t -= duration;
  }
}
BENCHMARK(BM_SampleVisemes);

void BM_ParseMarkup(benchmark::State& state) {
  const std::string markup =
      "<gaze at=\"viewer\"/><gesture name=\"Wave\"/>Hello! I am standing right here in your room; "
      "<face expr=\"happy\" intensity=\"0.6\"/>come closer and I will show you around.";
  for (auto _ : state) benchmark::DoNotOptimize(ParseMarkup(markup, "bench").tags.size());
}
BENCHMARK(BM_ParseMarkup);

}  // namespace
}  // namespace arview::speech

BENCHMARK_MAIN();
