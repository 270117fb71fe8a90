// bench_listen: what recognition costs and how soon a result follows speech (docs/listen.md,
// "Figures"). Needs Debian's pocketsphinx-en-us and pocketsphinx-testdata.
//   build/release/listen/bench_listen
// BM_Decode: an utterance through the Recognizer's thread as fast as it can go; the counter
//   real_time_factor is the decoding wall time over the audio's seconds (the worker's time in
//   the decoder; cpu_real_time_factor the worker thread's CPU time, which a loaded machine
//   does not inflate), for the package's goforward.raw with its five-word grammar, a dialogue's
//   twelve phrases, and those phrases with wildcards over the 500-word vocabulary.
// BM_Start: constructing a Recognizer (what a session pays once, before listening).
// BM_LatencyAfterRelease: push-to-talk, the utterance already decoded as it came; from
//   StopUtterance to the result.
// BM_LatencyAfterSpeech: voice activity, goforward.raw and 1.5 s of silence pushed in 20 ms
//   blocks at the real-time pace; from the end of the last word (where push-to-talk's decoding
//   puts it) to the result: the detector's wait for silence (vad_postspeech_frames: 20, the
//   default 30, and PocketSphinx's own 50 frames of 10 ms) plus the decoding. Each iteration
//   takes 4.3 s of real time.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <thread>

#include "base/stats.h"
#include "listen/recognizer.h"
#include "listen/test_listen_data.h"

namespace arview::listen {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const std::vector<std::string> kDialoguePhrases = {
    "hello", "hi there", "hello my name is *", "yes", "no", "what is your name", "go away",
    "come here", "tell me about *", "goodbye", "thank you", "show me the *", "go forward ten meters"};

std::vector<std::string> PhrasesFor(int grammar) {
  if (grammar == 0) return {"go forward ten meters", "go backward ten meters", "go forward five meters"};
  std::vector<std::string> phrases = kDialoguePhrases;
  if (grammar == 1) {
    phrases.erase(std::remove_if(phrases.begin(), phrases.end(),
                                 [](const std::string& p) { return p.find('*') != std::string::npos; }),
                  phrases.end());
  }
  return phrases;
}

const char* kGrammarLabels[] = {"3 phrases", "10 phrases", "13 phrases, 3 with *"};

bool HaveData(benchmark::State& state) {
  if (std::filesystem::exists(testing::kModelMdef) && std::filesystem::exists(testing::kTestdata / "goforward.raw")) {
    return true;
  }
  state.SkipWithError("needs the Debian packages pocketsphinx-en-us and pocketsphinx-testdata");
  return false;
}

void BM_Decode(benchmark::State& state) {
  if (!HaveData(state)) return;
  Recognizer recognizer(RecognizerOptions{}, PhrasesFor(static_cast<int>(state.range(0))));
  const std::vector<std::int16_t> speech = testing::LoadRaw(testing::kTestdata / "goforward.raw");
  std::string heard;
  for (auto _ : state) {
    recognizer.StartUtterance();
    recognizer.Push(speech);
    recognizer.StopUtterance();
    heard = recognizer.WaitResult(60s).value_or(Recognition{}).text;
  }
  const RecognizerStatistics statistics = recognizer.Statistics();
  const double audio_seconds = static_cast<double>(statistics.samples_decoded) / kSampleRate;
  state.counters["real_time_factor"] = statistics.decode_seconds / audio_seconds;
  state.counters["cpu_real_time_factor"] = statistics.decode_cpu_seconds / audio_seconds;
  state.SetLabel(std::string(kGrammarLabels[state.range(0)]) + ": \"" + heard + "\"");
}
BENCHMARK(BM_Decode)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Setting up: the acoustic model and dictionary, the 500-word wildcard vocabulary read from the
// 27 MB language model, the grammar compiled, the worker started.
void BM_Start(benchmark::State& state) {
  if (!HaveData(state)) return;
  for (auto _ : state) {
    Recognizer recognizer(RecognizerOptions{}, kDialoguePhrases);
    benchmark::DoNotOptimize(recognizer.WildcardWords().size());
  }
}
BENCHMARK(BM_Start)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LatencyAfterRelease(benchmark::State& state) {
  if (!HaveData(state)) return;
  Recognizer recognizer(RecognizerOptions{}, kDialoguePhrases);
  const std::vector<std::int16_t> speech = testing::LoadRaw(testing::kTestdata / "goforward.raw");
  std::vector<double> latencies;
  for (auto _ : state) {
    recognizer.StartUtterance();
    recognizer.Push(speech);
    recognizer.Drain();
    const auto released = Clock::now();
    recognizer.StopUtterance();
    const Recognition heard = recognizer.WaitResult(60s).value_or(Recognition{});
    const std::chrono::duration<double> latency = heard.made_at - released;
    latencies.push_back(latency.count());
    state.SetIterationTime(latency.count());
  }
  state.counters["median_ms"] = 1000 * Median(latencies);
  state.counters["p95_ms"] = 1000 * Percentile(latencies, 0.95);
}
BENCHMARK(BM_LatencyAfterRelease)->Iterations(20)->UseManualTime()->Unit(benchmark::kMillisecond);

void BM_LatencyAfterSpeech(benchmark::State& state) {
  if (!HaveData(state)) return;
  const std::vector<std::int16_t> speech = testing::LoadRaw(testing::kTestdata / "goforward.raw");
  // Where the words end, as push-to-talk's full decoding of the file puts it.
  std::int64_t words_end = 0;
  {
    Recognizer key(RecognizerOptions{}, kDialoguePhrases);
    key.StartUtterance();
    key.Push(speech);
    key.StopUtterance();
    words_end = key.WaitResult(60s).value_or(Recognition{}).end_sample;
  }
  std::vector<std::int16_t> input = speech;
  input.resize(speech.size() + 3 * kSampleRate / 2, 0);
  RecognizerOptions options;
  options.mode = ListenMode::kVoiceActivity;
  options.decoder.vad_postspeech_frames = static_cast<int>(state.range(0));
  std::vector<double> latencies;
  for (auto _ : state) {
    Recognizer recognizer(options, kDialoguePhrases);
    const auto start = Clock::now();
    constexpr std::size_t kBlock = 320;  // 20 ms, a capture period
    for (std::size_t done = 0; done < input.size(); done += kBlock) {
      std::this_thread::sleep_until(start + std::chrono::microseconds((done + kBlock) * 1'000'000 / kSampleRate));
      recognizer.Push(std::span(input).subspan(done, std::min(kBlock, input.size() - done)));
    }
    recognizer.Drain();
    double latency = -1;
    while (auto heard = recognizer.TakeResult()) {
      if (!heard->accepted) continue;
      const auto spoken_end = start + std::chrono::microseconds(words_end * 1'000'000 / kSampleRate);
      latency = std::chrono::duration<double>(heard->made_at - spoken_end).count();
    }
    if (latency < 0) {
      state.SkipWithError("goforward.raw was not recognized");
      return;
    }
    latencies.push_back(latency);
    state.SetIterationTime(latency);
  }
  state.counters["median_ms"] = 1000 * Median(latencies);
  state.counters["p95_ms"] = 1000 * Percentile(latencies, 0.95);
}
BENCHMARK(BM_LatencyAfterSpeech)->ArgName("postspeech_frames")->Arg(20)->Arg(30)->Arg(50)->Iterations(5)
    ->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arview::listen

BENCHMARK_MAIN();
