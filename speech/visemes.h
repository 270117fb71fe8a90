#pragma once
// Lip-sync: phones → the 15 visemes of Meta's and OpenXR's face tracking, through the thesis's
// SAPI 5.1 grouping (Egges' thesis, Appendix D), with its coarticulation (§5.3.1): each phone
// spans a dominance curve C_α(x) = e^(−2α|x−0.5|) − 2|x−0.5|·e^(−α), x ∈ [0,1] over `spread`
// times the phone's length centred on it, scaled by the viseme's weight; the visemes' weights at
// a time are the curves summed per viseme and divided by their total, as the MIRAnim schedule's
// linear frame blender averages its actions by weight (docs/speech.md).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "base/enum_table.h"
#include "speech/synthesizer.h"

namespace arview::speech {

enum class Viseme : std::uint8_t { kSil, kPP, kFF, kTH, kDD, kKk, kCH, kSS, kNn, kRR, kAa, kE, kIh, kOh, kOu };
inline constexpr std::size_t kVisemeCount = 15;
constexpr auto EnumNames(Viseme) {
  return EnumTable<Viseme, kVisemeCount>{{{Viseme::kSil, "sil"},
                                          {Viseme::kPP, "PP"},
                                          {Viseme::kFF, "FF"},
                                          {Viseme::kTH, "TH"},
                                          {Viseme::kDD, "DD"},
                                          {Viseme::kKk, "kk"},
                                          {Viseme::kCH, "CH"},
                                          {Viseme::kSS, "SS"},
                                          {Viseme::kNn, "nn"},
                                          {Viseme::kRR, "RR"},
                                          {Viseme::kAa, "aa"},
                                          {Viseme::kE, "E"},
                                          {Viseme::kIh, "ih"},
                                          {Viseme::kOh, "oh"},
                                          {Viseme::kOu, "ou"}}};
}

// The thesis's curve for one SAPI viseme (Appendix D.2).
struct CurveShape {
  double spread = 1;  // the curve's length in phone lengths
  double weight = 1;  // its height: how much the viseme counts against its neighbours
  double alpha = 1;   // its sharpness (C_α)
};

// One phone's row of the table (visemes.cpp, docs/speech.md).
struct PhoneVisemeRow {
  std::string_view phone;  // Flite's US phone set
  int sapi_viseme;         // SP_VISEME_<n> of SAPI 5.1, the thesis's grouping
  Viseme viseme;
  CurveShape shape;
};

std::span<const PhoneVisemeRow> PhoneVisemeTable();
// The row of `phone`; a SpeechError naming it when the table has no such phone.
const PhoneVisemeRow& PhoneVisemeRowOf(std::string_view phone);

// C_α(x) for x in [0,1]; 0 outside.
double Dominance(double alpha, double x);

using VisemeWeights = std::array<float, kVisemeCount>;

// A line's viseme curves, built once from its phones; Sample reads them at any time without
// allocating (a binary search and the curves that overlap the time).
class VisemeTrack {
 public:
  explicit VisemeTrack(std::span<const Phone> phones);

  // The 15 weights at `time_s` (seconds from the line's start), summing to 1; all silence
  // where no curve reaches (before the first phone, after the last).
  void Sample(double time_s, VisemeWeights& weights) const;

 private:
  struct Curve {
    double begin_s;
    double length_s;
    double weight;
    double alpha;
    Viseme viseme;
  };
  std::vector<Curve> curves_;  // by begin_s
  double longest_s_ = 0;
};

}  // namespace arview::speech
