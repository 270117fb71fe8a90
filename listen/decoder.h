#pragma once
// One PocketSphinx decoder (Debian's 0.8+5prealpha: the cmd_ln_t configuration, ps_init,
// ps_set_jsgf_string, ps_set_keyphrase). Not thread-safe: one thread owns it (the
// Recognizer's worker, or a test or benchmark). PocketSphinx's own log is kept off stderr; its
// error lines end up in the ListenError a failure throws.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace arview::listen {

inline constexpr int kSampleRate = 16000;      // Hz: the model's, and the input's
inline constexpr int kSamplesPerFrame = 160;   // PocketSphinx's 100 frames per second

struct DecoderOptions {
  // The acoustic model folder (mdef, means, variances, ...) and the pronunciation dictionary.
  std::filesystem::path model_dir = "/usr/share/pocketsphinx/model/en-us/en-us";
  std::filesystem::path dictionary = "/usr/share/pocketsphinx/model/en-us/cmudict-en-us.dict";
  // true: PocketSphinx's voice-activity detector drops non-speech frames and says when speech
  // is on (InSpeech); false: every frame of an utterance is decoded (push-to-talk).
  bool voice_activity = false;
  // Frames of non-speech that end speech for the detector (PocketSphinx's -vad_postspeech,
  // default 50): the wait after the last word before a result can be made.
  int vad_postspeech_frames = 30;
  // Keyword spotting's detection threshold (-kws_threshold): lower finds more, and more falsely.
  double wake_threshold = 1e-20;
};

// A word of a hypothesis; frames count from the start of the utterance (the frames the decoder
// saw: with voice_activity, non-speech frames before the speech are not counted).
struct DecodedWord {
  std::string word;
  int first_frame = 0;
  int last_frame = 0;  // inclusive
};

struct Hypothesis {
  std::string text;                 // the words, space-separated; empty when nothing matched
  std::vector<DecodedWord> words;   // fillers and silences left out
  // The words' acoustic log-likelihood per frame against the best senone of each frame (≤ 0, in
  // PocketSphinx's score units), and the geometric-mean likelihood ratio it gives, in (0, 1].
  double score_per_frame = 0;
  double confidence = 0;
  // The words' frames over their phones (the dictionary's first pronunciation): a grammar
  // forced onto noise stretches a short word over seconds.
  double frames_per_phone = 0;
  double posterior = 0;             // PocketSphinx's lattice posterior of the hypothesis
  int frames = 0;                   // frames the decoder searched in this utterance
};

class Decoder {
 public:
  // Throws ListenError naming the folder or file when the model or dictionary is missing or
  // PocketSphinx refuses them.
  explicit Decoder(const DecoderOptions& options);
  ~Decoder();
  Decoder(const Decoder&) = delete;
  Decoder& operator=(const Decoder&) = delete;

  // Compiles a JSGF grammar and makes it the search of the next utterance. Throws ListenError
  // with PocketSphinx's message when it does not compile, and naming each word the dictionary
  // lacks. Call between utterances.
  void UseGrammar(const std::string& jsgf);
  // Keyword spotting for one phrase as the search of the next utterance; throws ListenError
  // naming a word the dictionary lacks. Call between utterances.
  void UseWakePhrase(const std::string& phrase);
  // Switches between the searches already set up (between utterances).
  void SearchGrammar();
  void SearchWakePhrase();
  bool HasWakePhrase() const { return has_wake_phrase_; }

  // The vocabulary: whether the dictionary has a word (lowercase).
  bool Knows(const std::string& word) const;

  void StartUtterance();
  void Process(std::span<const std::int16_t> samples);
  // With voice_activity: whether the detector hears speech now.
  bool InSpeech() const;
  // The wake phrase's search only: whether the phrase has been spotted in this utterance.
  bool WakePhraseSpotted() const;
  Hypothesis EndUtterance();
  bool InUtterance() const { return in_utterance_; }

 private:
  struct Handles;
  std::unique_ptr<Handles> handles_;
  bool in_utterance_ = false;
  bool has_wake_phrase_ = false;
  bool searching_wake_ = false;
};

// The words a JSGF grammar can produce (its vocabulary, each once). Throws ListenError with
// SphinxBase's reason when the text does not parse or has no public rule. Needs no model, so a
// grammar can be checked on any thread.
std::vector<std::string> JsgfWords(const std::string& jsgf);

// The `count` most probable words of an ARPA or binary language model that `decoder` knows,
// most probable first (the default wildcard vocabulary). Throws ListenError naming the file.
std::vector<std::string> MostProbableWords(const std::filesystem::path& language_model,
                                           std::size_t count, const Decoder& decoder);

}  // namespace arview::listen
