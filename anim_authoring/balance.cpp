#include "anim_authoring/balance.h"

#include "anim/blending_params.h"
#include "anim/pose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arview::authoring {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The side's ankle (or foot) joint: the first joint below the leg's root named like one, else
// two joints below the leg's root (hip → knee → ankle). −1 without a leg.
int FootJoint(const anim::Skeleton& sk, bool left) {
  const int leg = anim::LegRoot(sk, left);
  if (leg < 0) return -1;
  for (int j : anim::Subtree(sk, leg)) {
    const std::string n = Lower(sk.names[j]);
    if (n.find("ankle") != std::string::npos || n.find("foot") != std::string::npos) return j;
  }
  int j = leg;
  for (int step = 0; step < 2; ++step) {
    int child = -1;
    for (int c = j + 1; c < sk.size() && child < 0; ++c)
      if (sk.parents[c] == j) child = c;
    if (child < 0) return -1;
    j = child;
  }
  return j;
}

// The nearest common ancestor of two joints (the pelvis above both legs), or a if none.
int CommonAncestor(const anim::Skeleton& sk, int a, int b) {
  for (int x = a; x >= 0; x = sk.parents[x])
    for (int y = b; y >= 0; y = sk.parents[y])
      if (x == y) return x;
  return a;
}

Eigen::Vector3d Horizontal(const Eigen::Vector3d& v, const Eigen::Vector3d& up) { return v - v.dot(up) * up; }

}  // namespace

int BalanceAnalysis::TransitionPairs() const {
  bool seen[3][3] = {};
  int pairs = 0;
  for (const Transition& t : transitions) {
    bool& s = seen[static_cast<int>(t.from_support)][static_cast<int>(t.to_support)];
    pairs += !s;
    s = true;
  }
  return pairs;
}

std::string BalanceAnalysis::Summary() const {
  char buf[1024];
  std::snprintf(buf, sizeof(buf),
                "%s: %.1f s, %d frames, body height %.3g; both feet planted %.2f s (longest run %.2f s; "
                "pelvis over the left foot %.2f s, between %.2f s, over the right %.2f s), resting %.2f s; %zu rests of %.2g s or more, %zu transitions "
                "(%d category pairs)",
                source.c_str(), seconds, frames, height, planted_seconds, longest_planted_seconds, planted_by_support[0],
                planted_by_support[1], planted_by_support[2], resting_seconds, rests.size(), min_rest_seconds, transitions.size(),
                TransitionPairs());
  return buf;
}

BalanceAnalysis AnalyseBalance(const anim::Skeleton& sk, const anim::Clip& clip, const BalanceOptions& o, const std::string& source) {
  auto named = [&](const std::string& name) {
    const int j = sk.Find(name);
    if (j < 0) throw anim::Error(source + ": no joint '" + name + "'");
    return j;
  };
  const int left = o.left_foot.empty() ? FootJoint(sk, true) : named(o.left_foot);
  const int right = o.right_foot.empty() ? FootJoint(sk, false) : named(o.right_foot);
  if (left < 0 || right < 0)
    throw anim::Error(source + ": no left and right foot found by name (balance needs both legs)");
  std::vector<int> pelvis;
  for (const std::string& n : o.pelvis) pelvis.push_back(named(n));
  if (pelvis.empty()) pelvis.push_back(CommonAncestor(sk, anim::LegRoot(sk, true), anim::LegRoot(sk, false)));
  const Eigen::Vector3d up = o.up.normalized();
  BalanceAnalysis a;
  a.source = source;
  a.min_rest_seconds = o.min_rest_seconds;
  a.seconds = clip.duration;
  a.frames = std::max(1, static_cast<int>(std::floor(clip.duration * o.rate)) + 1);
  // Per frame: feet and pelvis positions, and the body's extent along up (its height: the
  // median over the frames, so that marker data without a rest pose is measured too).
  anim::LocalPose pose = anim::LocalPose::Rest(sk);
  std::vector<Eigen::Matrix4d> model(sk.size());
  std::vector<Eigen::Vector3d> lf(a.frames), rf(a.frames), pv(a.frames);
  std::vector<double> extent(a.frames);
  for (int f = 0; f < a.frames; ++f) {
    anim::MustRun(anim::SamplingJob{&sk, &clip, f / o.rate, false, &pose}, "balance");
    anim::MustRun(anim::LocalToModelJob{&sk, &pose, model}, "balance");
    lf[f] = model[left].block<3, 1>(0, 3);
    rf[f] = model[right].block<3, 1>(0, 3);
    pv[f].setZero();
    for (int j : pelvis) pv[f] += model[j].block<3, 1>(0, 3) / static_cast<double>(pelvis.size());
    double lo = 1e300, hi = -1e300;
    for (const auto& m : model) {
      lo = std::min(lo, up.dot(m.block<3, 1>(0, 3)));
      hi = std::max(hi, up.dot(m.block<3, 1>(0, 3)));
    }
    extent[f] = hi - lo;
  }
  std::nth_element(extent.begin(), extent.begin() + a.frames / 2, extent.end());
  a.height = extent[a.frames / 2] > 0 ? extent[a.frames / 2] : 1.0;
  const double dt = 1.0 / o.rate;
  std::vector<bool> planted(a.frames, false), resting(a.frames, false);
  std::vector<anim::Support> support(a.frames, anim::Support::kBoth);
  double run = 0;
  for (int f = 1; f < a.frames; ++f) {
    const double foot_speed = std::max((lf[f] - lf[f - 1]).norm(), (rf[f] - rf[f - 1]).norm()) * o.rate / a.height;
    const double pelvis_speed = Horizontal(pv[f] - pv[f - 1], up).norm() * o.rate / a.height;
    const Eigen::Vector3d d = Horizontal(rf[f] - lf[f], up);
    const double s = d.squaredNorm() > 0 ? Horizontal(pv[f] - lf[f], up).dot(d) / d.squaredNorm() : 0.5;
    support[f] = s < o.one_foot ? anim::Support::kLeft : s > 1 - o.one_foot ? anim::Support::kRight : anim::Support::kBoth;
    planted[f] = foot_speed < o.max_foot_speed;
    resting[f] = planted[f] && pelvis_speed < o.max_rest_speed;
    if (planted[f]) {
      a.planted_seconds += dt;
      a.planted_by_support[static_cast<int>(support[f])] += dt;
      run += dt;
      a.longest_planted_seconds = std::max(a.longest_planted_seconds, run);
    } else {
      run = 0;
    }
    if (resting[f]) a.resting_seconds += dt;
  }
  // Rests: runs of resting frames of one category.
  const int min_frames = static_cast<int>(std::ceil(o.min_rest_seconds * o.rate));
  std::vector<std::pair<int, int>> rest_frames;
  for (int f = 1; f < a.frames;) {
    if (!resting[f]) {
      ++f;
      continue;
    }
    int e = f;
    while (e < a.frames && resting[e] && support[e] == support[f]) ++e;
    if (e - f >= min_frames) {
      a.rests.push_back({support[f], f / o.rate, (e - 1) / o.rate});
      rest_frames.emplace_back(f, e - 1);
    }
    f = e;
  }
  // Transitions: between consecutive rests of different categories, feet planted throughout.
  for (std::size_t r = 1; r < a.rests.size(); ++r) {
    if (a.rests[r].support == a.rests[r - 1].support) continue;
    bool on_feet = true;
    for (int f = rest_frames[r - 1].second; f <= rest_frames[r].first && on_feet; ++f) on_feet = planted[f];
    if (on_feet)
      a.transitions.push_back(
          {a.rests[r - 1].support, a.rests[r].support, a.rests[r - 1].to, a.rests[r].from, static_cast<int>(r) - 1});
  }
  return a;
}

namespace {

// Keeps the transitions after which the walk can always go on: a transition into a category
// with no recorded way out is dropped, and so on until nothing changes.
void KeepLeavable(anim::BalanceModel& m) {
  for (bool changed = true; changed;) {
    changed = false;
    for (int s = 0; s < anim::kSupports; ++s) {
      if (m.CanLeave(static_cast<anim::Support>(s))) continue;
      for (int c = 0; c < anim::kSupports; ++c)
        if (m.counts[c][s] > 0) {
          m.counts[c][s] = 0;
          changed = true;
        }
    }
  }
}

// The recording's transitions as segments (postures from the end of one rest to the start of
// the next), with the dwell before each (the rest it leaves) per category.
void AddTransitions(const BalanceAnalysis& a, const std::vector<Eigen::VectorXd>& postures, double rate, anim::BalanceModel& m,
                    std::array<std::vector<double>, anim::kSupports>& dwell) {
  for (const BalanceAnalysis::Transition& t : a.transitions) {
    anim::BalanceModel::Segment segment;
    segment.from = t.from_support;
    segment.to = t.to_support;
    segment.rate = rate;
    segment.recorded_at = t.from;
    const long last = std::min(std::lround(t.to * rate), static_cast<long>(postures.size()) - 1);
    for (long f = std::lround(t.from * rate); f <= last; ++f) segment.frames.push_back(postures[f]);
    m.segments.push_back(std::move(segment));
    ++m.counts[static_cast<int>(t.from_support)][static_cast<int>(t.to_support)];
    const BalanceAnalysis::Rest& rest = a.rests[t.rest];
    dwell[static_cast<int>(t.from_support)].push_back(rest.to - rest.from);
  }
}

std::string Seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", s);
  return buf;
}

}  // namespace

std::optional<anim::BalanceModel> LearnBalanceModel(const anim::Skeleton& character, const IdleSource& source, const anim::IdleModel& idle,
                                              const IdleLearningOptions& idle_options, const BalanceLearningOptions& options,
                                              BalanceLearningReport* report) {
  BalanceLearningReport rep;
  rep.source = source.data->source;
  anim::BalanceModel m;
  std::array<std::vector<double>, anim::kSupports> dwell;
  const double rate = options.analysis.rate;
  // What each clip holds first: a recording without a transition needs no postures.
  for (const anim::Clip* clip : source.clips) {
    BalanceAnalysis a = AnalyseBalance(source.data->skeleton, *clip, options.analysis, source.data->source + " " + clip->name);
    for (const BalanceAnalysis::Rest& r : a.rests) ++rep.rests[static_cast<int>(r.support)];
    rep.transitions += static_cast<int>(a.transitions.size());
    rep.clips.push_back(std::move(a));
  }
  for (std::size_t i = 0; i < source.clips.size() && rep.transitions > 0; ++i) {
    if (rep.clips[i].transitions.empty()) continue;
    std::vector<int> joints;
    const std::vector<Eigen::VectorXd> postures = ClipPostures(character, source, *source.clips[i], idle_options, rate, &joints);
    if (joints != idle.joints)
      throw anim::Error(rep.clips[i].source + ": maps onto other joints than the idle model's sources; learn both from one kind of rig");
    AddTransitions(rep.clips[i], postures, rate, m, dwell);
  }
  KeepLeavable(m);
  std::erase_if(m.segments, [&](const anim::BalanceModel::Segment& s) {
    return m.counts[static_cast<int>(s.from)][static_cast<int>(s.to)] == 0;
  });
  for (const anim::BalanceModel::Segment& s : m.segments) {
    m.rests[static_cast<int>(s.from)].push_back(s.frames.front());
    m.rests[static_cast<int>(s.to)].push_back(s.frames.back());
  }
  for (int c = 0; c < anim::kSupports; ++c)
    if (m.CanLeave(static_cast<anim::Support>(c))) {
      m.dwell_min[c] = *std::min_element(dwell[c].begin(), dwell[c].end());
      m.dwell_max[c] = *std::max_element(dwell[c].begin(), dwell[c].end());
    }
  m.joints = idle.joints;
  m.root = idle.root;
  m.mean = idle.mean;
  const int k = std::min(options.components, idle.component_count());
  m.components = idle.components.leftCols(k);
  m.eigenvalues = idle.eigenvalues.head(k);
  rep.learned = !m.segments.empty();
  rep.segments = static_cast<int>(m.segments.size());
  rep.counts = m.counts;
  rep.dwell_min = m.dwell_min;
  rep.dwell_max = m.dwell_max;
  rep.components = k;
  if (report) *report = rep;
  if (!rep.learned) return std::nullopt;
  m.Check(character.size());
  return m;
}

std::string BalanceLearningReport::Summary() const {
  double seconds = 0;
  for (const BalanceAnalysis& a : clips) seconds += a.seconds;
  std::string s = source + ": " + std::to_string(clips.size()) + (clips.size() == 1 ? " clip, " : " clips, ") + Seconds(seconds) +
                  " s; rests (" + Seconds(clips.empty() ? 0.0 : clips.front().min_rest_seconds) + " s or more): left " +
                  std::to_string(rests[0]) + ", both " + std::to_string(rests[1]) + ", right " + std::to_string(rests[2]) +
                  "; " + std::to_string(transitions) + " transitions";
  if (!learned) {
    return s + (transitions == 0 ? ": nothing to learn balance shifts from"
                                 : ": none leads to a category the recording also leaves, so no walk can go on");
  }
  s += "; learned " + std::to_string(segments) + " segments:";
  for (int c = 0; c < anim::kSupports; ++c) {
    const int total = counts[c][0] + counts[c][1] + counts[c][2];
    if (total == 0) continue;
    s += std::string(" ") + anim::SupportName(static_cast<anim::Support>(c)) + " (dwell " + Seconds(dwell_min[c]) + "-" +
         Seconds(dwell_max[c]) + " s) to";
    for (int t = 0; t < anim::kSupports; ++t)
      if (counts[c][t] > 0)
        s += std::string(" ") + anim::SupportName(static_cast<anim::Support>(t)) + " " + std::to_string(counts[c][t]) + "/" +
             std::to_string(total);
    s += ";";
  }
  return s + " distance over " + std::to_string(components) + " components";
}

}  // namespace arview::authoring
