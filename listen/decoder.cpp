#include "listen/decoder.h"

#include <pocketsphinx.h>
#include <sphinxbase/err.h>
#include <sphinxbase/fsg_model.h>
#include <sphinxbase/jsgf.h>
#include <sphinxbase/ngram_model.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <utility>

#include "listen/listen_error.h"

namespace arview::listen {
namespace {

// PocketSphinx keeps its scores in logmath units shifted right by SENSCR_SHIFT (acmod.h, not an
// installed header): one unit of a word's acoustic score is 2^10 logmath steps.
constexpr double kScoreShift = 1024.0;

// The last error and warning lines SphinxBase logged on this thread: PocketSphinx reports why a
// grammar or a model failed only there. Its info lines (hundreds per decoder) are dropped.
thread_local std::string t_sphinx_errors;

void KeepSphinxErrors(void* /*user_data*/, err_lvl_t level, const char* format, ...) {
  if (level != ERR_WARN && level != ERR_ERROR && level != ERR_FATAL) return;
  char line[512];
  va_list arguments;
  va_start(arguments, format);
  std::vsnprintf(line, sizeof line, format, arguments);
  va_end(arguments);
  std::string text(line);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  if (text.empty()) return;
  if (!t_sphinx_errors.empty()) t_sphinx_errors += "; ";
  t_sphinx_errors += text;
  if (t_sphinx_errors.size() > 2000) t_sphinx_errors.erase(0, t_sphinx_errors.size() - 2000);
}

void RouteSphinxLog() {
  static std::once_flag once;
  std::call_once(once, [] {
    err_set_logfp(nullptr);  // ps_init prints its whole configuration to the log file otherwise
    err_set_callback(KeepSphinxErrors, nullptr);
  });
}

// What SphinxBase said since the last call, for the end of an error line.
std::string TakeSphinxErrors() {
  std::string errors = std::move(t_sphinx_errors);
  t_sphinx_errors.clear();
  return errors.empty() ? std::string("PocketSphinx gave no reason") : "PocketSphinx: " + errors;
}

// PocketSphinx reads these; a model folder without them would end the process in its loader
// (E_FATAL calls exit), so they are checked first.
constexpr const char* kModelFiles[] = {"mdef", "means", "variances", "transition_matrices", "noisedict"};

void CheckModelFiles(const DecoderOptions& options) {
  const auto& dir = options.model_dir;
  if (!std::filesystem::is_directory(dir)) {
    throw ListenError("listen: no acoustic model folder " + dir.string() +
                      " (the default comes from the Debian package pocketsphinx-en-us)");
  }
  for (const char* name : kModelFiles) {
    if (!std::filesystem::is_regular_file(dir / name)) {
      throw ListenError("listen: the acoustic model folder " + dir.string() + " has no " + name +
                        " (a PocketSphinx model has mdef, means, variances, transition_matrices and noisedict)");
    }
  }
  if (!std::filesystem::is_regular_file(options.dictionary)) {
    throw ListenError("listen: no pronunciation dictionary " + options.dictionary.string() +
                      " (the default comes from the Debian package pocketsphinx-en-us)");
  }
}

// Silences and noises (<sil>, [NOISE]), and "(NULL)": a grammar's empty transition (an optional
// part of a JSGF rule not taken).
bool IsFiller(const std::string& word) {
  return word.empty() || word.front() == '<' || word.front() == '[' || word.front() == '+' || word.front() == '(';
}

std::size_t CountPhones(const char* pronunciation) {
  std::size_t phones = 0;
  bool in_phone = false;
  for (const char* c = pronunciation; *c; ++c) {
    const bool space = *c == ' ';
    if (!space && !in_phone) ++phones;
    in_phone = !space;
  }
  return phones;
}

// "read(2)" → "read": the dictionary's alternative pronunciations are one word to the caller.
std::string BaseWord(std::string word) {
  if (const auto paren = word.find('('); paren != std::string::npos && paren > 0) word.resize(paren);
  return word;
}

// The phones of a word, or of each word of a key phrase (keyword spotting gives the phrase as
// one segment); a word the dictionary lacks counts one.
std::size_t PhonesOf(ps_decoder_t* ps, const std::string& words) {
  std::size_t phones = 0;
  std::size_t start = 0;
  while (start < words.size()) {
    const std::size_t end = std::min(words.find(' ', start), words.size());
    if (end > start) {
      char* pronunciation = ps_lookup_word(ps, words.substr(start, end - start).c_str());
      phones += pronunciation ? CountPhones(pronunciation) : 1;
      std::free(pronunciation);
    }
    start = end + 1;
  }
  return phones;
}

}  // namespace

struct Decoder::Handles {
  cmd_ln_t* config = nullptr;
  ps_decoder_t* decoder = nullptr;
  ~Handles() {
    if (decoder) ps_free(decoder);
    if (config) cmd_ln_free_r(config);
  }
};

Decoder::Decoder(const DecoderOptions& options) : handles_(std::make_unique<Handles>()) {
  RouteSphinxLog();
  CheckModelFiles(options);
  t_sphinx_errors.clear();
  const std::string model = options.model_dir.string();
  const std::string dictionary = options.dictionary.string();
  const std::string postspeech = std::to_string(options.vad_postspeech_frames);
  char threshold[32];
  std::snprintf(threshold, sizeof threshold, "%g", options.wake_threshold);
  handles_->config = cmd_ln_init(nullptr, ps_args(), TRUE,
                                 "-hmm", model.c_str(),
                                 "-dict", dictionary.c_str(),
                                 "-remove_silence", options.voice_activity ? "yes" : "no",
                                 "-vad_postspeech", postspeech.c_str(),
                                 "-kws_threshold", threshold,
                                 nullptr);
  if (!handles_->config) throw ListenError("listen: PocketSphinx refused its configuration; " + TakeSphinxErrors());
  handles_->decoder = ps_init(handles_->config);
  if (!handles_->decoder) {
    throw ListenError("listen: PocketSphinx could not load the model " + model + " with the dictionary " +
                      dictionary + "; " + TakeSphinxErrors());
  }
}

Decoder::~Decoder() = default;

void Decoder::UseGrammar(const std::string& jsgf) {
  t_sphinx_errors.clear();
  if (ps_set_jsgf_string(handles_->decoder, "grammar", jsgf.c_str()) < 0) {
    throw ListenError("listen: the grammar does not compile; " + TakeSphinxErrors());
  }
  SearchGrammar();
}

void Decoder::UseWakePhrase(const std::string& phrase) {
  std::string word;
  for (std::size_t i = 0; i <= phrase.size(); ++i) {
    if (i < phrase.size() && phrase[i] != ' ') {
      word += phrase[i];
      continue;
    }
    if (!word.empty() && !Knows(word)) {
      throw ListenError("listen: the wake phrase \"" + phrase + "\" has the word '" + word +
                        "', which the pronunciation dictionary does not have");
    }
    word.clear();
  }
  t_sphinx_errors.clear();
  if (ps_set_keyphrase(handles_->decoder, "wake", phrase.c_str()) < 0) {
    throw ListenError("listen: the wake phrase \"" + phrase + "\" was refused; " + TakeSphinxErrors());
  }
  has_wake_phrase_ = true;
  SearchWakePhrase();
}

void Decoder::SearchGrammar() {
  ps_set_search(handles_->decoder, "grammar");
  searching_wake_ = false;
}

void Decoder::SearchWakePhrase() {
  ps_set_search(handles_->decoder, "wake");
  searching_wake_ = true;
}

bool Decoder::Knows(const std::string& word) const {
  char* phones = ps_lookup_word(handles_->decoder, word.c_str());
  const bool known = phones != nullptr;
  std::free(phones);
  return known;
}

void Decoder::StartUtterance() {
  // A new stream for each utterance: PocketSphinx then counts the words' frames from this
  // utterance's first sample, the frames its voice-activity detector dropped included.
  ps_start_stream(handles_->decoder);
  if (ps_start_utt(handles_->decoder) < 0) throw ListenError("listen: PocketSphinx could not start an utterance; " + TakeSphinxErrors());
  in_utterance_ = true;
}

void Decoder::Process(std::span<const std::int16_t> samples) {
  if (samples.empty()) return;
  if (ps_process_raw(handles_->decoder, samples.data(), samples.size(), FALSE, FALSE) < 0) {
    throw ListenError("listen: PocketSphinx failed on the audio; " + TakeSphinxErrors());
  }
}

bool Decoder::InSpeech() const { return ps_get_in_speech(handles_->decoder) != 0; }

bool Decoder::WakePhraseSpotted() const {
  if (!searching_wake_) return false;
  const char* hypothesis = ps_get_hyp(handles_->decoder, nullptr);
  return hypothesis != nullptr && *hypothesis != '\0';
}

Hypothesis Decoder::EndUtterance() {
  ps_decoder_t* ps = handles_->decoder;
  ps_end_utt(ps);
  in_utterance_ = false;
  Hypothesis result;
  result.frames = ps_get_n_frames(ps);
  logmath_t* logmath = ps_get_logmath(ps);
  std::int64_t acoustic = 0;
  int word_frames = 0;
  std::size_t phones = 0;
  for (ps_seg_t* seg = ps_seg_iter(ps); seg; seg = ps_seg_next(seg)) {
    const std::string word = BaseWord(ps_seg_word(seg));
    if (IsFiller(word)) continue;
    int first = 0;
    int last = 0;
    ps_seg_frames(seg, &first, &last);
    int32 word_acoustic = 0;
    int32 language = 0;
    int32 backoff = 0;
    ps_seg_prob(seg, &word_acoustic, &language, &backoff);
    acoustic += word_acoustic;
    word_frames += last - first + 1;
    phones += PhonesOf(ps, word);
    if (!result.text.empty()) result.text += ' ';
    result.text += word;
    result.words.push_back({word, first, last});
  }
  if (word_frames > 0) {
    result.score_per_frame = static_cast<double>(acoustic) / word_frames;
    result.confidence = searching_wake_ ? 0.0 : std::exp(result.score_per_frame * kScoreShift * std::log(logmath_get_base(logmath)));
    result.frames_per_phone = static_cast<double>(word_frames) / static_cast<double>(phones);
    result.posterior = searching_wake_ ? 1.0 : logmath_exp(logmath, ps_get_prob(ps));
  }
  return result;
}

std::vector<std::string> JsgfWords(const std::string& jsgf) {
  RouteSphinxLog();
  t_sphinx_errors.clear();
  jsgf_t* grammar = jsgf_parse_string(jsgf.c_str(), nullptr);
  if (!grammar) throw ListenError("listen: the grammar does not compile; " + TakeSphinxErrors());
  jsgf_rule_t* rule = jsgf_get_public_rule(grammar);
  if (!rule) {
    jsgf_grammar_free(grammar);
    throw ListenError("listen: the grammar has no public rule; a JSGF grammar needs one (\"public <name> = ...;\")");
  }
  logmath_t* logmath = logmath_init(1.0001, 0, 0);
  fsg_model_t* fsg = jsgf_build_fsg(grammar, rule, logmath, 1.0);
  std::vector<std::string> words;
  if (fsg) {
    for (int i = 0; i < fsg_model_n_word(fsg); ++i) words.emplace_back(fsg_model_word_str(fsg, i));
    fsg_model_free(fsg);
  }
  logmath_free(logmath);
  jsgf_grammar_free(grammar);
  if (!fsg) throw ListenError("listen: the grammar does not compile; " + TakeSphinxErrors());
  return words;
}

std::vector<std::string> MostProbableWords(const std::filesystem::path& language_model,
                                           std::size_t count, const Decoder& decoder) {
  RouteSphinxLog();
  if (!std::filesystem::is_regular_file(language_model)) {
    throw ListenError("listen: no language model " + language_model.string() +
                      " for the wildcard vocabulary (the default comes from the Debian package pocketsphinx-en-us)");
  }
  logmath_t* logmath = logmath_init(1.0001, 0, 0);
  t_sphinx_errors.clear();
  ngram_model_t* model = ngram_model_read(nullptr, language_model.c_str(), NGRAM_AUTO, logmath);
  if (!model) {
    logmath_free(logmath);
    throw ListenError("listen: could not read the language model " + language_model.string() + "; " + TakeSphinxErrors());
  }
  // Debian's SphinxBase has no m-gram iterator: the unigrams are the word ids 0..count-1, each
  // scored alone (no history).
  std::vector<std::pair<int32, std::string>> scored;
  const uint32 unigrams = ngram_model_get_counts(model)[0];
  int32 history = 0;
  for (int32 id = 0; id < static_cast<int32>(unigrams); ++id) {
    std::string word = ngram_word(model, id);
    const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || c == '\'';
    });
    if (plain) scored.emplace_back(ngram_ng_score(model, id, &history, 0, &history), std::move(word));
  }
  ngram_model_free(model);
  logmath_free(logmath);
  std::stable_sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::string> words;
  for (auto& [score, word] : scored) {
    if (words.size() == count) break;
    if (decoder.Knows(word)) words.push_back(std::move(word));
  }
  return words;
}

}  // namespace arview::listen
