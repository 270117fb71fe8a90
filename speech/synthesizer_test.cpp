#include "speech/synthesizer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "speech/speech_queue.h"

namespace arview::speech {
namespace {

using ::testing::HasSubstr;

TEST(Synthesizer, GivesSixteenKilohertzAudioAndPhonesThatTileTheLine) {
  const SpokenLine line = Synthesizer(Voice::kSlt).Synthesize("Hello, I am the figure in your room.");
  ASSERT_FALSE(line.samples.empty());
  ASSERT_GE(line.phones.size(), 20u);
  EXPECT_EQ(line.phones.front().name, "pau");
  EXPECT_DOUBLE_EQ(line.phones.front().start_s, 0.0);
  for (std::size_t i = 1; i < line.phones.size(); ++i) {
    EXPECT_DOUBLE_EQ(line.phones[i].start_s, line.phones[i - 1].end_s) << i;
    EXPECT_GE(line.phones[i].end_s, line.phones[i].start_s) << i;
  }
  // The phones end where the audio does, within a 5 ms frame of Flite's synthesis.
  EXPECT_NEAR(line.phones.back().end_s, line.DurationSeconds(), 0.05);
  bool any_loud = false;
  for (const std::int16_t sample : line.samples) any_loud = any_loud || sample > 3000 || sample < -3000;
  EXPECT_TRUE(any_loud);
}

TEST(Synthesizer, GivesEachTokenTheStartOfItsFirstPhone) {
  const SpokenLine line = Synthesizer(Voice::kSlt).Synthesize("Hello there -- I am 42.");
  ASSERT_EQ(line.tokens.size(), 6u);
  EXPECT_EQ(line.tokens[0].name, "Hello");
  EXPECT_EQ(line.tokens[2].name, "--");
  EXPECT_FALSE(line.tokens[2].start_s.has_value());  // Flite says nothing for "--"
  EXPECT_EQ(line.tokens[5].name, "42");
  // "hello" starts with hh, after the leading pause.
  ASSERT_TRUE(line.tokens[0].start_s.has_value());
  EXPECT_DOUBLE_EQ(*line.tokens[0].start_s, line.phones[0].end_s);
  EXPECT_EQ(line.phones[1].name, "hh");
  double previous = 0;
  for (const SpokenToken& token : line.tokens) {
    if (!token.start_s) continue;
    EXPECT_GT(*token.start_s, previous) << token.name;
    previous = *token.start_s;
  }
}

TEST(Synthesizer, TheSameLineTwiceGivesTheSameBytesAndPhones) {
  for (const Voice voice : {Voice::kSlt, Voice::kRms, Voice::kAwb}) {
    const Synthesizer synthesizer(voice);
    const SpokenLine first = synthesizer.Synthesize("Would you like to see the map of this room?");
    const SpokenLine second = synthesizer.Synthesize("Would you like to see the map of this room?");
    EXPECT_EQ(first.samples, second.samples) << ToString(voice);
    ASSERT_EQ(first.phones.size(), second.phones.size()) << ToString(voice);
    for (std::size_t i = 0; i < first.phones.size(); ++i) {
      EXPECT_EQ(first.phones[i].name, second.phones[i].name);
      EXPECT_EQ(first.phones[i].start_s, second.phones[i].start_s);
      EXPECT_EQ(first.phones[i].end_s, second.phones[i].end_s);
    }
  }
}

TEST(Synthesizer, VoicesDiffer) {
  const std::string text = "Good morning.";
  EXPECT_NE(Synthesizer(Voice::kSlt).Synthesize(text).samples, Synthesizer(Voice::kAwb).Synthesize(text).samples);
}

TEST(Synthesizer, AnUnknownVoiceIsOneErrorNamingIt) {
  try {
    (void)VoiceFromName("kal");
    FAIL() << "no error";
  } catch (const SpeechError& error) {
    EXPECT_THAT(error.what(), HasSubstr("'kal'"));
    EXPECT_THAT(error.what(), HasSubstr("slt, rms or awb"));
  }
  EXPECT_EQ(VoiceFromName("rms"), Voice::kRms);
}

TEST(Synthesizer, RefusesANulByte) {
  EXPECT_THROW((void)Synthesizer(Voice::kSlt).Synthesize(std::string("hello\0there", 11)), SpeechError);
}

TEST(Synthesizer, EmptyTextGivesNoWordsAndNoCrash) {
  const SpokenLine line = Synthesizer(Voice::kSlt).Synthesize("");
  EXPECT_TRUE(line.tokens.empty());
}

TEST(Synthesizer, SynthesizersOnTwoThreadsGiveWhatOneGivesAlone) {
  const std::string text = "Two threads share one lock around Flite.";
  const SpokenLine alone = Synthesizer(Voice::kSlt).Synthesize(text);
  SpokenLine a, b;
  {
    std::jthread first([&] { a = Synthesizer(Voice::kSlt).Synthesize(text); });
    std::jthread second([&] { b = Synthesizer(Voice::kRms).Synthesize(text); });
  }
  EXPECT_EQ(a.samples, alone.samples);
  EXPECT_FALSE(b.samples.empty());
}

SpeechResult WaitForResult(SpeechQueue& queue) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::optional<SpeechResult> result = queue.TakeFinished()) return std::move(*result);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ADD_FAILURE() << "no result within 60 s";
  return {};
}

TEST(SpeechQueue, SynthesizesAheadAndHandsLinesBackInOrder) {
  SpeechQueue queue(Voice::kSlt, 2);
  EXPECT_FALSE(queue.TakeFinished().has_value());
  ASSERT_TRUE(queue.Submit(7, "Hello."));
  ASSERT_TRUE(queue.Submit(8, "Goodbye."));
  EXPECT_FALSE(queue.Submit(9, "One too many.")) << "the queue holds 2 lines";
  const SpeechResult first = WaitForResult(queue);
  EXPECT_EQ(first.id, 7u);
  EXPECT_TRUE(first.error.empty());
  EXPECT_EQ(first.line.samples, Synthesizer(Voice::kSlt).Synthesize("Hello.").samples);
  EXPECT_EQ(WaitForResult(queue).id, 8u);
  EXPECT_EQ(queue.Pending(), 0u);
  EXPECT_TRUE(queue.Submit(9, "Now there is room."));
}

TEST(SpeechQueue, AFailedLineComesBackWithItsError) {
  SpeechQueue queue(Voice::kAwb, 1);
  ASSERT_TRUE(queue.Submit(1, std::string("bad\0line", 8)));
  const SpeechResult result = WaitForResult(queue);
  EXPECT_EQ(result.id, 1u);
  EXPECT_THAT(result.error, HasSubstr("NUL"));
}

TEST(SpeechQueue, StopsWithLinesStillWaiting) {
  SpeechQueue queue(Voice::kSlt, 3);
  EXPECT_TRUE(queue.Submit(1, "A line that is dropped when the queue goes."));
  EXPECT_TRUE(queue.Submit(2, "And another."));
}

TEST(SpeechQueue, RefusesNoCapacity) { EXPECT_THROW(SpeechQueue(Voice::kSlt, 0), SpeechError); }

}  // namespace
}  // namespace arview::speech
