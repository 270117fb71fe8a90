// Noise, silence and music must not become commands (issue 54): five minutes of generated
// input through the recognizer in each mode, with a grammar of a dialogue's phrases (wildcards
// included, the loosest kind), must give no accepted result and no wake phrase. The figures
// each run prints (what was heard and how close it came to each gate) are in docs/listen.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>

#include "listen/recognizer.h"
#include "listen/test_listen_data.h"
#include "tests/support/test_data.h"

namespace arview::listen {
namespace {

using namespace std::chrono_literals;

const std::vector<std::string> kDialoguePhrases = {
    "hello", "hi there", "hello my name is *", "yes", "no", "what is your name", "go away",
    "come here", "tell me about *", "goodbye", "thank you", "show me the *"};

constexpr std::size_t kSegment = 10 * kSampleRate;  // ten seconds of each kind, in turn
constexpr double kMinutes = 5;

struct Closest {
  std::size_t results = 0;
  std::size_t with_words = 0;
  // Results with words that each gate alone refuses (RecognizerOptions' defaults).
  std::size_t low_confidence = 0, too_slow = 0, unvoiced = 0, steady = 0;
  double confidence = 0;         // the highest of any result with words
  double seconds_per_phone = 1e9;  // the lowest
  double voiced_fraction = 0;    // the highest
};

// Feeds kMinutes of the kinds in turn (new seeds each round); push-to-talk holds the key over
// each segment. Returns the accepted results; prints how close the others came.
std::vector<Recognition> HearNoise(const RecognizerOptions& options) {
  Recognizer recognizer(options, kDialoguePhrases);
  const std::vector<testing::NoiseKind> kinds = testing::NoiseKinds(kSegment);
  const auto segments = static_cast<std::size_t>(kMinutes * 60 * kSampleRate / kSegment);
  std::vector<Recognition> accepted;
  Closest closest;
  for (std::size_t i = 0; i < segments; ++i) {
    const testing::NoiseKind& kind = kinds[i % kinds.size()];
    const std::vector<std::int16_t> samples = kind.make(static_cast<std::uint32_t>(54 + i));
    if (options.mode == ListenMode::kPushToTalk) recognizer.StartUtterance();
    for (std::size_t done = 0; done < samples.size(); done += 1600) {
      recognizer.Push(std::span(samples).subspan(done, std::min<std::size_t>(1600, samples.size() - done)));
      recognizer.Drain();  // the queue would drop input pushed faster than real time beyond 10 s
    }
    if (options.mode == ListenMode::kPushToTalk) recognizer.StopUtterance();
    recognizer.Drain();
    while (auto heard = recognizer.TakeResult()) {
      ++closest.results;
      if (heard->accepted) {
        std::printf("  ACCEPTED from %s: \"%s\" confidence %.3f\n", kind.name.c_str(), heard->text.c_str(), heard->confidence);
        accepted.push_back(*heard);
      }
      if (heard->kind == HeardKind::kWakePhrase && !heard->accepted) {
        std::printf("  the wake phrase spotted in %s, refused: %.3f s/phone, voiced %.2f, steady pitch %.2f s\n",
                    kind.name.c_str(), heard->seconds_per_phone, heard->voiced_fraction, heard->steady_pitch_s);
      }
      if (heard->text.empty() || heard->kind != HeardKind::kCommand) continue;
      ++closest.with_words;
      const RecognizerOptions defaults;
      closest.low_confidence += heard->confidence < defaults.min_confidence ? 1 : 0;
      closest.too_slow += heard->seconds_per_phone > defaults.max_seconds_per_phone ? 1 : 0;
      closest.unvoiced += heard->voiced_fraction < defaults.min_voiced_fraction ? 1 : 0;
      closest.steady += heard->steady_pitch_s > defaults.max_steady_pitch_s ? 1 : 0;
      closest.confidence = std::max(closest.confidence, heard->confidence);
      closest.seconds_per_phone = std::min(closest.seconds_per_phone, heard->seconds_per_phone);
      closest.voiced_fraction = std::max(closest.voiced_fraction, heard->voiced_fraction);
    }
  }
  const RecognizerStatistics statistics = recognizer.Statistics();
  std::printf("%.0f s of input: %zu results, %zu with words (highest confidence %.3f, shortest %.3f s/phone, "
              "most voiced %.2f; refused by confidence %zu, by length %zu, by voicing %zu, by steady pitch %zu), "
              "%lld accepted, %lld wake phrases; decoding took %.1f s\n",
              static_cast<double>(statistics.samples_pushed) / kSampleRate, closest.results, closest.with_words,
              closest.confidence, closest.with_words ? closest.seconds_per_phone : 0.0, closest.voiced_fraction,
              closest.low_confidence, closest.too_slow, closest.unvoiced, closest.steady,
              static_cast<long long>(statistics.accepted), static_cast<long long>(statistics.wake_phrases),
              statistics.decode_seconds);
  return accepted;
}

#define REQUIRE_MODEL() ARVIEW_REQUIRE_DATA_PATH(testing::kModelMdef, testing::kModelPackage)

TEST(RecognizerOnNoise, FiveMinutesWithTheKeyHeldAcceptNothing) {
  REQUIRE_MODEL();
  EXPECT_TRUE(HearNoise(RecognizerOptions{}).empty());
}

TEST(RecognizerOnNoise, FiveMinutesOfVoiceActivityAcceptNothing) {
  REQUIRE_MODEL();
  RecognizerOptions options;
  options.mode = ListenMode::kVoiceActivity;
  EXPECT_TRUE(HearNoise(options).empty());
}

TEST(RecognizerOnNoise, FiveMinutesWaitingForTheWakePhraseHearNothing) {
  REQUIRE_MODEL();
  RecognizerOptions options;
  options.mode = ListenMode::kVoiceActivity;
  options.wake_phrase = "hey figure";
  EXPECT_TRUE(HearNoise(options).empty());
}

}  // namespace
}  // namespace arview::listen
