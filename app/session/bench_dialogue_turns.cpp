// Turn-taking latency (issue 54): over the scripted exchange of test_dialogue_exchange.h, from the
// end of each of the user's lines (known from the WAV) to the first sample of the character's
// reply, with the frame clock at real time (30 fps, the WAV paced by it). One exchange per voice
// of the user's side (slt, rms, awb); the counters are over its turns, and the median and 95th
// percentile over all three are printed at the end. docs/listen.md, "Turn-taking latency".
//
//   ARVIEW_SOURCE_DIR=$PWD build/release/app/session/bench_session

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <unistd.h>

#include "app/session/test_dialogue_exchange.h"
#include "base/stats.h"
#include "tests/support/test_data.h"

namespace {

using namespace arview;

std::vector<double> all_latencies_ms;     // from the end of the heard words (as --stats records)
std::vector<double> all_from_wav_end_ms;  // from the end of each line's samples in the WAV

double Percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5))];
}

void BM_TurnLatency(benchmark::State& state) {
  const speech::Voice voice = static_cast<speech::Voice>(state.range(0));
  const std::filesystem::path wav =
      std::filesystem::temp_directory_path() / ("arview_bench_turns_" + std::to_string(::getpid()) + ".wav");
  const app::testing::UserSide user = app::testing::SynthesizeUserSide(app::testing::kUserLines, voice);
  app::testing::WriteSpeechWav(wav, user.samples);
  std::vector<double> latencies_ms, from_wav_end_ms;
  std::size_t turns_on_path = 0;
  for (auto _ : state) {
    const app::testing::ExchangeRun run = app::testing::RunExchange(
        app::testing::SpokenDialogue(arview::testing::SourceDir()), wav, "slt", 1.0, 90);
    for (const std::string& p : run.problems) std::fprintf(stderr, "problem: %s\n", p.c_str());
    for (const std::string& r : run.results) std::fprintf(stderr, "heard at %s\n", r.c_str());
    for (const app::DialogueTurnRecord& t : run.turns) {
      std::fprintf(stderr, "%s  t %6.2f s  heard \"%s\" (%.3f, ends %.2f s)  %s: %s  said at %.2f s, latency %.0f ms\n",
                   ToString(voice).c_str(), t.time_s, t.heard.c_str(), t.confidence, t.heard_end_s, t.machine.c_str(),
                   t.said.c_str(), t.reply_start_s, 1000 * t.LatencyS());
      if (t.LatencyS() >= 0) latencies_ms.push_back(1000 * t.LatencyS());
      // The same from the end of the line's samples in the WAV (Flite's trailing silence included).
      const auto line = std::find(app::testing::kUserLines.begin(), app::testing::kUserLines.end(), t.heard);
      if (line != app::testing::kUserLines.end() && t.reply_start_s >= 0)
        from_wav_end_ms.push_back(1000 * (t.reply_start_s - user.line_end_s[line - app::testing::kUserLines.begin()]));
      turns_on_path += !t.heard.empty();
    }
  }
  std::filesystem::remove(wav);
  all_latencies_ms.insert(all_latencies_ms.end(), latencies_ms.begin(), latencies_ms.end());
  all_from_wav_end_ms.insert(all_from_wav_end_ms.end(), from_wav_end_ms.begin(), from_wav_end_ms.end());
  state.counters["turns"] = static_cast<double>(latencies_ms.size());
  state.counters["heard_turns"] = static_cast<double>(turns_on_path);
  if (latencies_ms.empty()) return;
  state.counters["median_ms"] = Median(latencies_ms);
  state.counters["p95_ms"] = Percentile(latencies_ms, 0.95);
  state.counters["max_ms"] = *std::max_element(latencies_ms.begin(), latencies_ms.end());
}
BENCHMARK(BM_TurnLatency)->DenseRange(0, 2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (!all_latencies_ms.empty())
    std::printf("from the end of the heard words: %zu turns, latency median %.0f ms, p95 %.0f ms, max %.0f ms\n", all_latencies_ms.size(),
                Median(all_latencies_ms), Percentile(all_latencies_ms, 0.95),
                *std::max_element(all_latencies_ms.begin(), all_latencies_ms.end()));
  if (!all_from_wav_end_ms.empty())
    std::printf("from the end of each line in the WAV: %zu turns, median %.0f ms, p95 %.0f ms, max %.0f ms\n",
                all_from_wav_end_ms.size(), Median(all_from_wav_end_ms), Percentile(all_from_wav_end_ms, 0.95),
                *std::max_element(all_from_wav_end_ms.begin(), all_from_wav_end_ms.end()));
}
