// bench_dialogue: what one DialogueManager::Update costs the thread that runs it
// (docs/dialogue.md, "Figures").
//   build/release/dialogue/bench_dialogue
// On the demo dialogue (docs/examples/guide-dialogue.yaml): an update with nothing heard (every
// frame's: the decay, the time and viewer conditions of six machines), and one with a phrase
// heard (a turn: the patterns of every running machine matched, a transition made).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>

#include "dialogue/dialogue.h"

namespace arview::dialogue {
namespace {

Dialogue Demo() {
  const char* source = std::getenv("ARVIEW_SOURCE_DIR");
  return LoadDialogue(std::filesystem::path(source ? source : ".") / "docs/examples/guide-dialogue.yaml");
}

void BM_UpdateNothingHeard(benchmark::State& state) {
  DialogueManager manager(Demo(), 0);
  const DialogueInput input{1.0 / 30, std::nullopt, {true, 1.5, true, true}};
  for (auto _ : state) benchmark::DoNotOptimize(manager.Update(input));
}
BENCHMARK(BM_UpdateNothingHeard);

void BM_UpdateHeard(benchmark::State& state) {
  DialogueManager manager(Demo(), 0);
  manager.Update({0.0, std::nullopt, {true, 1.5, true, true}});  // the greeting
  manager.Update({1.0, "my name is ann", {true, 1.5, true, true}});
  // Praise: the feelings machine answers and restarts (cyclic), so every iteration is a turn.
  const DialogueInput input{1.0, "you are really quite wonderful today", {true, 1.5, true, true}};
  for (auto _ : state) benchmark::DoNotOptimize(manager.Update(input));
}
BENCHMARK(BM_UpdateHeard);

void BM_ExpectedPhrases(benchmark::State& state) {
  const DialogueManager manager(Demo(), 0);
  for (auto _ : state) benchmark::DoNotOptimize(manager.ExpectedPhrases());
}
BENCHMARK(BM_ExpectedPhrases);

}  // namespace
}  // namespace arview::dialogue

BENCHMARK_MAIN();
