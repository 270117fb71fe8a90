#include "listen/recognizer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "listen/listen_error.h"
#include "listen/test_listen_data.h"
#include "tests/support/test_data.h"

namespace arview::listen {
namespace {

using namespace std::chrono_literals;
using testing::kModelMdef;
using testing::kModelPackage;
using testing::kTestdata;
using testing::kTestdataPackage;
using ::testing::HasSubstr;

#define REQUIRE_MODEL_AND_TESTDATA()                                  \
  do {                                                                \
    ARVIEW_REQUIRE_DATA_PATH(kModelMdef, kModelPackage);              \
    ARVIEW_REQUIRE_DATA_PATH(kTestdata / "goforward.raw", kTestdataPackage); \
  } while (0)

std::string ReadText(const std::filesystem::path& path) {
  const std::vector<char> bytes = testing::FileBytes(path);
  return {bytes.begin(), bytes.end()};
}

std::vector<std::int16_t> Cards(const std::string& id) { return testing::LoadTestWav(kTestdata / "cards" / (id + ".wav")); }
std::vector<std::int16_t> GoForward() { return testing::LoadRaw(kTestdata / "goforward.raw"); }

// Pushes `samples` in 100 ms blocks, as a capture thread would.
void PushInBlocks(Recognizer& recognizer, const std::vector<std::int16_t>& samples) {
  const std::span<const std::int16_t> all(samples);
  for (std::size_t done = 0; done < all.size(); done += 1600) {
    ASSERT_TRUE(recognizer.Push(all.subspan(done, std::min<std::size_t>(1600, all.size() - done))));
  }
}

Recognition HearWithTheKeyHeld(Recognizer& recognizer, const std::vector<std::int16_t>& samples) {
  recognizer.StartUtterance();
  PushInBlocks(recognizer, samples);
  recognizer.StopUtterance();
  std::optional<Recognition> heard = recognizer.WaitResult(60s);
  if (!heard) ADD_FAILURE() << "no result within 60 s";
  return heard.value_or(Recognition{});
}

std::string ErrorOf(const std::function<void()>& call) {
  try {
    call();
  } catch (const ListenError& error) {
    return error.what();
  }
  return "";
}

RecognizerOptions PushToTalk() { return RecognizerOptions{}; }

RecognizerOptions VoiceActivity() {
  RecognizerOptions options;
  options.mode = ListenMode::kVoiceActivity;
  return options;
}

// The package's human recordings with the package's grammars: cards/ (five recordings of
// playing cards, cards.gram, cards.transcription) and goforward.raw (goforward.gram, "go forward
// ten meters"). Word accuracy over all of them; docs/listen.md reports the figure.
TEST(RecognizerOnTestdata, TheHumanRecordingsWithTheirGrammarsAreHeardAsTranscribed) {
  REQUIRE_MODEL_AND_TESTDATA();
  Recognizer recognizer(PushToTalk(), {"hello"});
  recognizer.ListenJsgf(ReadText(kTestdata / "cards/cards.gram"));
  std::vector<std::pair<std::string, Recognition>> heard;  // reference, result
  for (const auto& [id, words] : testing::ReadTranscription(kTestdata / "cards/cards.transcription")) {
    heard.emplace_back(words, HearWithTheKeyHeld(recognizer, Cards(id)));
  }
  recognizer.ListenJsgf(ReadText(kTestdata / "goforward.gram"));
  heard.emplace_back("go forward ten meters", HearWithTheKeyHeld(recognizer, GoForward()));

  std::size_t words = 0, errors = 0, accepted = 0;
  for (const auto& [reference, result] : heard) {
    const std::size_t wrong = testing::WordErrors(testing::Words(reference), testing::Words(result.text));
    words += testing::Words(reference).size();
    errors += wrong;
    accepted += result.accepted ? 1 : 0;
    std::printf("  said \"%s\", heard \"%s\": %zu errors, confidence %.3f, %.3f s/phone, voiced %.2f, "
                "steady pitch %.2f s, %s\n",
                reference.c_str(), result.text.c_str(), wrong, result.confidence, result.seconds_per_phone,
                result.voiced_fraction, result.steady_pitch_s, result.accepted ? "accepted" : "rejected");
  }
  const double accuracy = 1.0 - static_cast<double>(errors) / static_cast<double>(words);
  std::printf("word accuracy %.1f%% (%zu errors in %zu words), %zu of %zu utterances accepted\n", 100 * accuracy,
              errors, words, accepted, heard.size());
  EXPECT_GE(accuracy, 0.95);
  EXPECT_EQ(accepted, heard.size());
}

TEST(RecognizerOnTestdata, TheKeyHeldGivesTheWordsTimesInTheInputsSampleClock) {
  REQUIRE_MODEL_AND_TESTDATA();
  Recognizer recognizer(PushToTalk(), {"go forward ten meters"});
  const std::vector<std::int16_t> before = testing::Silence(12345);
  ASSERT_TRUE(recognizer.Push(before));  // outside the key: skipped, but the clock runs
  const Recognition heard = HearWithTheKeyHeld(recognizer, GoForward());
  ASSERT_EQ(heard.text, "go forward ten meters");
  ASSERT_EQ(heard.words.size(), 4u);
  // goforward.raw's speech runs from about 0.46 s to 2.12 s (where its energy is; the
  // decoder's segmentation agrees within 50 ms).
  EXPECT_NEAR((heard.start_sample - 12345) / 16000.0, 0.46, 0.1);
  EXPECT_NEAR((heard.end_sample - 12345) / 16000.0, 2.12, 0.1);
  EXPECT_EQ(heard.ended_at_sample, 12345 + static_cast<std::int64_t>(GoForward().size()));
  for (std::size_t i = 1; i < heard.words.size(); ++i) {
    EXPECT_LE(heard.words[i - 1].end_sample, heard.words[i].start_sample);
  }
}

TEST(RecognizerOnTestdata, VoiceActivityFindsEachUtteranceWhereItIs) {
  REQUIRE_MODEL_AND_TESTDATA();
  Recognizer recognizer(VoiceActivity(), {"go forward ten meters", "four queen of clubs"});
  const std::vector<std::int16_t> cards = Cards("002");
  const std::vector<std::int16_t> go = GoForward();
  const std::vector<std::int16_t> pause = testing::Silence(16000);
  for (const auto* part : {&cards, &pause, &go, &pause}) PushInBlocks(recognizer, *part);
  recognizer.Drain();
  std::vector<Recognition> accepted;
  while (auto heard = recognizer.TakeResult()) {
    if (heard->accepted) accepted.push_back(*heard);
  }
  ASSERT_EQ(accepted.size(), 2u);
  EXPECT_EQ(accepted[0].text, "four queen of clubs");
  EXPECT_EQ(accepted[1].text, "go forward ten meters");
  const auto go_start = static_cast<std::int64_t>(cards.size() + pause.size());
  EXPECT_NEAR((accepted[1].start_sample - go_start) / 16000.0, 0.46, 0.1);
  EXPECT_NEAR((accepted[1].end_sample - go_start) / 16000.0, 2.12, 0.1);
  // The detector's end of speech: vad_postspeech_frames (0.3 s) of silence after the words,
  // seen within one 20 ms chunk.
  EXPECT_GE(accepted[1].ended_at_sample, accepted[1].end_sample);
  EXPECT_LE(accepted[1].ended_at_sample - accepted[1].end_sample, 16000 * 6 / 10);
}

TEST(RecognizerOnTestdata, AWildcardTakesWordsOfItsVocabulary) {
  REQUIRE_MODEL_AND_TESTDATA();
  RecognizerOptions options = PushToTalk();
  options.wildcard_words = {"forward", "backward", "left", "ten", "five", "two"};
  Recognizer recognizer(options, {"go * meters", "stop"});
  const Recognition heard = HearWithTheKeyHeld(recognizer, GoForward());
  EXPECT_EQ(heard.text, "go forward ten meters");
  EXPECT_TRUE(heard.accepted);
}

TEST(RecognizerOnTestdata, TheDefaultWildcardVocabularyIsTheLanguageModelsCommonestWords) {
  REQUIRE_MODEL_AND_TESTDATA();
  Recognizer recognizer(PushToTalk(), {"hello"});
  const std::vector<std::string>& words = recognizer.WildcardWords();
  EXPECT_EQ(words.size(), 500u);
  for (const char* common : {"the", "of", "and", "to", "you"}) {
    EXPECT_NE(std::find(words.begin(), words.end(), common), words.end()) << common;
  }
}

TEST(RecognizerOnTestdata, NewPhrasesApplyFromTheNextUtterance) {
  REQUIRE_MODEL_AND_TESTDATA();
  Recognizer recognizer(PushToTalk(), {"turn left", "yes"});
  const Recognition before = HearWithTheKeyHeld(recognizer, GoForward());
  EXPECT_FALSE(before.accepted && before.text == "go forward ten meters");
  recognizer.Listen({"go forward ten meters", "turn left"});
  const Recognition after = HearWithTheKeyHeld(recognizer, GoForward());
  EXPECT_EQ(after.text, "go forward ten meters");
  EXPECT_TRUE(after.accepted);
}

// Read speech from a novel (librivox/) forced onto the cards grammar: the words come out as
// cards, and the confidence gate refuses every one.
TEST(RecognizerOnTestdata, SpeechOutsideTheGrammarIsNotAccepted) {
  REQUIRE_MODEL_AND_TESTDATA();
  Recognizer recognizer(PushToTalk(), {"hello"});
  recognizer.ListenJsgf(ReadText(kTestdata / "cards/cards.gram"));
  for (const auto& entry : std::filesystem::directory_iterator(kTestdata / "librivox")) {
    if (entry.path().extension() != ".wav") continue;
    const Recognition heard = HearWithTheKeyHeld(recognizer, testing::LoadTestWav(entry.path()));
    std::printf("  %s heard as \"%s\": confidence %.4f, %.3f s/phone, voiced %.2f, steady pitch %.2f s\n",
                entry.path().filename().c_str(), heard.text.c_str(), heard.confidence, heard.seconds_per_phone,
                heard.voiced_fraction, heard.steady_pitch_s);
    EXPECT_FALSE(heard.accepted) << entry.path() << " heard as \"" << heard.text << "\", confidence "
                                 << heard.confidence;
  }
}

TEST(RecognizerOnTestdata, TheWakePhraseOpensTheNextUtteranceForACommand) {
  REQUIRE_MODEL_AND_TESTDATA();
  RecognizerOptions options = VoiceActivity();
  options.wake_phrase = "go forward";
  Recognizer recognizer(options, {"five five", "four queen of clubs"});
  const std::vector<std::int16_t> pause = testing::Silence(16000);
  // Before the wake phrase, a command is not taken.
  for (const auto& part : {Cards("004"), pause, GoForward(), pause, Cards("004"), pause}) PushInBlocks(recognizer, part);
  recognizer.Drain();
  std::vector<Recognition> results;
  while (auto heard = recognizer.TakeResult()) {
    if (heard->accepted) results.push_back(*heard);
  }
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].kind, HeardKind::kWakePhrase);
  EXPECT_EQ(results[0].text, "go forward");
  EXPECT_EQ(results[1].kind, HeardKind::kCommand);
  EXPECT_EQ(results[1].text, "five five");
  const auto second_cards = static_cast<std::int64_t>(Cards("004").size() + 2 * pause.size() + GoForward().size());
  EXPECT_GE(results[1].start_sample, second_cards);
}

TEST(RecognizerOnTestdata, PushNeverWaitsForTheDecoderAndDropsBeyondItsQueue) {
  REQUIRE_MODEL_AND_TESTDATA();
  RecognizerOptions options = PushToTalk();
  options.max_queued_s = 1.0;
  Recognizer recognizer(options, {"go forward ten meters"});
  recognizer.StartUtterance();
  const std::vector<std::int16_t> go = GoForward();        // 2.8 s: more than the queue holds
  EXPECT_FALSE(recognizer.Push(go));
  recognizer.Drain();
  EXPECT_TRUE(recognizer.Push(std::span(go).first(8000)));  // half a second fits
  recognizer.StopUtterance();
  ASSERT_TRUE(recognizer.WaitResult(60s).has_value());
  const RecognizerStatistics statistics = recognizer.Statistics();
  EXPECT_EQ(statistics.samples_dropped, static_cast<std::int64_t>(go.size()));
  EXPECT_EQ(statistics.samples_pushed, static_cast<std::int64_t>(go.size()) + 8000);
  EXPECT_EQ(statistics.samples_decoded, 8000);
}

TEST(RecognizerOnTestdata, BadPhrasesAreOneLineAndChangeNothing) {
  REQUIRE_MODEL_AND_TESTDATA();
  Recognizer recognizer(PushToTalk(), {"go forward ten meters"});
  EXPECT_EQ(ErrorOf([&] { recognizer.Listen({"hello xyzzyq"}); }),
            "listen: the pattern \"hello xyzzyq\" has the word 'xyzzyq', which the pronunciation dictionary does not have");
  EXPECT_EQ(ErrorOf([&] { recognizer.ListenJsgf(ReadText(kTestdata / "defective.gram")); }),
            "listen: the grammar has the word 'really_bad_word', which the pronunciation dictionary does not have");
  const std::string syntax = ErrorOf([&] { recognizer.ListenJsgf("#JSGF V1.0;\ngrammar g;\npublic <a> = (go | ;\n"); });
  EXPECT_THAT(syntax, HasSubstr("listen: the grammar does not compile; PocketSphinx: "));
  EXPECT_EQ(syntax.find('\n'), std::string::npos) << syntax;
  EXPECT_EQ(ErrorOf([&] { recognizer.ListenJsgf("#JSGF V1.0;\ngrammar g;\n<a> = go;\n"); }),
            "listen: the grammar has no public rule; a JSGF grammar needs one (\"public <name> = ...;\")");
  // The grammar before the refusals is still the one listened with.
  EXPECT_EQ(HearWithTheKeyHeld(recognizer, GoForward()).text, "go forward ten meters");
}

TEST(RecognizerOnTestdata, AWakePhraseIsCheckedAgainstTheDictionaryAndTheMode) {
  REQUIRE_MODEL_AND_TESTDATA();
  RecognizerOptions voice = VoiceActivity();
  voice.wake_phrase = "hey xyzzyq";
  EXPECT_EQ(ErrorOf([&] { Recognizer(voice, {"yes"}); }),
            "listen: the wake phrase \"hey xyzzyq\" has the word 'xyzzyq', which the pronunciation dictionary does not have");
  RecognizerOptions key = PushToTalk();
  key.wake_phrase = "hey figure";
  EXPECT_EQ(ErrorOf([&] { Recognizer(key, {"yes"}); }),
            "listen: a wake phrase (\"hey figure\") needs voice-activity mode: push-to-talk's key already says when to listen");
}

TEST(ListenErrors, AnOptionOutOfItsRangeIsOneLineNamingIt) {
  RecognizerOptions options;
  options.min_confidence = 1.5;
  EXPECT_EQ(ErrorOf([&] { Recognizer(options, {"yes"}); }),
            "listen: RecognizerOptions::min_confidence must be in [0, 1], not 1.5");
  options = RecognizerOptions{};
  options.decoder.vad_postspeech_frames = 0;
  EXPECT_EQ(ErrorOf([&] { Recognizer(options, {"yes"}); }),
            "listen: RecognizerOptions::decoder.vad_postspeech_frames must be at least 1, not 0");
}

// A missing model needs no model installed: these run everywhere.
TEST(ListenErrors, AMissingModelIsOneLineNamingTheFolder) {
  RecognizerOptions options;
  options.decoder.model_dir = "/nonexistent/en-us";
  EXPECT_EQ(ErrorOf([&] { Recognizer(options, {"yes"}); }),
            "listen: no acoustic model folder /nonexistent/en-us (the default comes from the Debian package "
            "pocketsphinx-en-us)");
}

TEST(ListenErrors, AModelFolderWithoutItsFilesIsOneLineNamingTheFile) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "arview-listen-half-model";
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "mdef") << "not a model";
  RecognizerOptions options;
  options.decoder.model_dir = folder;
  EXPECT_EQ(ErrorOf([&] { Recognizer(options, {"yes"}); }),
            "listen: the acoustic model folder " + folder.string() +
                " has no means (a PocketSphinx model has mdef, means, variances, transition_matrices and noisedict)");
  std::filesystem::remove_all(folder);
}

TEST(ListenErrors, AMissingDictionaryIsOneLineNamingIt) {
  ARVIEW_REQUIRE_DATA_PATH(kModelMdef, kModelPackage);
  RecognizerOptions options;
  options.decoder.dictionary = "/nonexistent/words.dict";
  EXPECT_EQ(ErrorOf([&] { Recognizer(options, {"yes"}); }),
            "listen: no pronunciation dictionary /nonexistent/words.dict (the default comes from the Debian package "
            "pocketsphinx-en-us)");
}

}  // namespace
}  // namespace arview::listen
