#include "speech/visemes.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace arview::speech {
namespace {

// Appendix D.2 of the thesis, per SAPI viseme: silence spreads over 2 phone lengths, vowels
// (1–11) over 5, consonants (12–21) over 3; the lips' closures (18 f v, 21 p b m) weigh 1.5, and
// p b m alone are sharper (α 3) so that the lips shut at the phone's centre.
constexpr CurveShape kSilence{2.0, 1.0, 1.0};
constexpr CurveShape kVowel{5.0, 1.0, 1.0};
constexpr CurveShape kConsonantLight{3.0, 0.9, 1.0};  // 12 h, 13 r, 14 l, 17 th dh
constexpr CurveShape kConsonant{3.0, 1.1, 1.0};       // 15 s z, 19 d t n, 20 k g ng
constexpr CurveShape kPostalveolar{3.0, 1.2, 1.0};    // 16 sh ch jh zh
constexpr CurveShape kLabiodental{3.0, 1.5, 1.0};     // 18 f v
constexpr CurveShape kBilabial{3.0, 1.5, 3.0};        // 21 p b m

// Flite's US phone set (cmu_us_*'s phoneset: the 39 CMU phones, pau, and the few variants its
// lexicon and letter-to-sound rules can give) → SAPI viseme → Meta/OpenXR viseme.
constexpr PhoneVisemeRow kTable[] = {
    {"pau", 0, Viseme::kSil, kSilence},      {"h#", 0, Viseme::kSil, kSilence},
    {"brk", 0, Viseme::kSil, kSilence},      {"ae", 1, Viseme::kAa, kVowel},
    {"ax", 1, Viseme::kAa, kVowel},          {"ah", 1, Viseme::kAa, kVowel},
    {"aa", 2, Viseme::kAa, kVowel},          {"ao", 3, Viseme::kOh, kVowel},
    {"ey", 4, Viseme::kE, kVowel},           {"eh", 4, Viseme::kE, kVowel},
    {"uh", 4, Viseme::kE, kVowel},           {"er", 5, Viseme::kRR, kVowel},
    {"axr", 5, Viseme::kRR, kVowel},         {"y", 6, Viseme::kIh, kVowel},
    {"iy", 6, Viseme::kIh, kVowel},          {"ih", 6, Viseme::kIh, kVowel},
    {"w", 7, Viseme::kOu, kVowel},           {"uw", 7, Viseme::kOu, kVowel},
    {"ow", 8, Viseme::kOh, kVowel},          {"aw", 9, Viseme::kAa, kVowel},
    {"oy", 10, Viseme::kOh, kVowel},         {"ay", 11, Viseme::kAa, kVowel},
    {"hh", 12, Viseme::kKk, kConsonantLight}, {"hv", 12, Viseme::kKk, kConsonantLight},
    {"r", 13, Viseme::kRR, kConsonantLight}, {"l", 14, Viseme::kNn, kConsonantLight},
    {"el", 14, Viseme::kNn, kConsonantLight}, {"s", 15, Viseme::kSS, kConsonant},
    {"z", 15, Viseme::kSS, kConsonant},      {"sh", 16, Viseme::kCH, kPostalveolar},
    {"ch", 16, Viseme::kCH, kPostalveolar},  {"jh", 16, Viseme::kCH, kPostalveolar},
    {"zh", 16, Viseme::kCH, kPostalveolar},  {"th", 17, Viseme::kTH, kConsonantLight},
    {"dh", 17, Viseme::kTH, kConsonantLight}, {"f", 18, Viseme::kFF, kLabiodental},
    {"v", 18, Viseme::kFF, kLabiodental},    {"d", 19, Viseme::kDD, kConsonant},
    {"t", 19, Viseme::kDD, kConsonant},      {"dx", 19, Viseme::kDD, kConsonant},
    {"n", 19, Viseme::kNn, kConsonant},      {"en", 19, Viseme::kNn, kConsonant},
    {"nx", 19, Viseme::kNn, kConsonant},     {"k", 20, Viseme::kKk, kConsonant},
    {"g", 20, Viseme::kKk, kConsonant},      {"ng", 20, Viseme::kKk, kConsonant},
    {"p", 21, Viseme::kPP, kBilabial},       {"b", 21, Viseme::kPP, kBilabial},
    {"m", 21, Viseme::kPP, kBilabial},       {"em", 21, Viseme::kPP, kBilabial},
};

}  // namespace

std::span<const PhoneVisemeRow> PhoneVisemeTable() { return kTable; }

const PhoneVisemeRow& PhoneVisemeRowOf(std::string_view phone) {
  for (const PhoneVisemeRow& row : kTable)
    if (row.phone == phone) return row;
  throw SpeechError("speech: the phone '" + std::string(phone) + "' has no viseme in the table (speech/visemes.cpp)");
}

double Dominance(double alpha, double x) {
  if (!(x >= 0.0 && x <= 1.0)) return 0.0;
  const double distance = 2.0 * std::abs(x - 0.5);
  return std::max(0.0, std::exp(-alpha * distance) - distance * std::exp(-alpha));
}

VisemeTrack::VisemeTrack(std::span<const Phone> phones) {
  curves_.reserve(phones.size());
  for (const Phone& phone : phones) {
    const PhoneVisemeRow& row = PhoneVisemeRowOf(phone.name);
    const double length = phone.end_s - phone.start_s;
    if (!(length > 0.0)) continue;  // a phone of no length has no curve to span
    const double curve_length = row.shape.spread * length;
    const double centre = 0.5 * (phone.start_s + phone.end_s);
    curves_.push_back({centre - 0.5 * curve_length, curve_length, row.shape.weight, row.shape.alpha, row.viseme});
    longest_s_ = std::max(longest_s_, curve_length);
  }
  std::stable_sort(curves_.begin(), curves_.end(),
                   [](const Curve& a, const Curve& b) { return a.begin_s < b.begin_s; });
}

void VisemeTrack::Sample(double time_s, VisemeWeights& weights) const {
  weights.fill(0.0f);
  // Curves that begin after time_s cannot reach it; those that begin more than the longest
  // curve's length before it have ended.
  const auto after = std::upper_bound(curves_.begin(), curves_.end(), time_s,
                                      [](double t, const Curve& curve) { return t < curve.begin_s; });
  // Each viseme counts with its strongest curve here (docs/speech.md, "Coarticulation": summing
  // them, two vowels of one viseme outweighed the lips' closure between them).
  double strongest[kVisemeCount] = {};
  for (auto it = after; it != curves_.begin();) {
    --it;
    if (it->begin_s < time_s - longest_s_) break;
    const double value = it->weight * Dominance(it->alpha, (time_s - it->begin_s) / it->length_s);
    double& viseme = strongest[static_cast<std::size_t>(it->viseme)];
    viseme = std::max(viseme, value);
  }
  double total = 0.0;
  for (const double value : strongest) total += value;
  if (!(total > 0.0)) {
    weights[static_cast<std::size_t>(Viseme::kSil)] = 1.0f;
    return;
  }
  for (std::size_t v = 0; v < kVisemeCount; ++v) weights[v] = static_cast<float>(strongest[v] / total);
}

}  // namespace arview::speech
