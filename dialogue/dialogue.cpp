#include "dialogue/dialogue.h"

#include <algorithm>
#include <cmath>

namespace arview::dialogue {

DialogueManager::DialogueManager(Dialogue dialogue, std::uint64_t seed)
    : dialogue_(std::move(dialogue)),
      emotions_(dialogue_.personality, dialogue_.decay_per_s),
      running_(dialogue_.machines.size()),
      random_(seed) {
  for (std::size_t m = 0; m < dialogue_.machines.size(); ++m) running_[m].state = dialogue_.machines[m].start;
  for (const dialogue::Variable& v : dialogue_.variables) values_.push_back(v.initial);
}

bool DialogueManager::Holds(const Condition& c, const Running& run, const DialogueInput& input, bool heard_available,
                            std::vector<std::string>& captures) const {
  if (const std::optional<bool> viewer_holds = ViewerConditionHolds(c, input.viewer)) return *viewer_holds;
  switch (c.kind) {
    case Condition::Kind::kHeard:
      if (!heard_available) return false;
      for (const Pattern& p : c.patterns)
        if (auto matched = p.Match(*input.heard)) {
          captures = std::move(*matched);
          return true;
        }
      return false;
    case Condition::Kind::kAboveThreshold: return emotions_.Intensity(c.emotion) > c.value;
    case Condition::Kind::kBelowThreshold: return emotions_.Intensity(c.emotion) < c.value;
    case Condition::Kind::kVariableEquals: return *Variable(c.variable) == c.text;
    case Condition::Kind::kVariableDiffers: return *Variable(c.variable) != c.text;
    case Condition::Kind::kInStateLongerThan: return run.seconds_in_state > c.value;
    default: return false;  // the viewer's, above
  }
}

std::optional<DialogueManager::Enabled> DialogueManager::FirstEnabled(std::size_t machine, const DialogueInput& input,
                                                                      bool heard_available) const {
  const Running& run = running_[machine];
  if (run.finished) return std::nullopt;
  const Machine& m = dialogue_.machines[machine];
  for (std::size_t t = 0; t < m.transitions.size(); ++t) {
    const Transition& transition = m.transitions[t];
    if (transition.from != run.state) continue;
    std::vector<std::string> captures;
    const bool all = std::all_of(transition.conditions.begin(), transition.conditions.end(), [&](const Condition& c) {
      return Holds(c, run, input, heard_available, captures);
    });
    if (all) return Enabled{machine, t, std::move(captures)};
  }
  return std::nullopt;
}

std::string DialogueManager::Fill(const std::string& text, const std::vector<std::string>& captures) const {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '$' || i + 1 >= text.size()) {
      out += text[i];
      continue;
    }
    const char next = text[i + 1];
    if (next == '$') {
      out += '$';
      ++i;
    } else if (next >= '1' && next <= '9') {
      const std::size_t n = static_cast<std::size_t>(next - '1');
      if (n < captures.size()) out += captures[n];
      ++i;
    } else if (next == '{') {
      const std::size_t close = text.find('}', i);
      out += Variable(text.substr(i + 2, close - i - 2)).value_or("");
      i = close;
    } else {
      out += '$';
    }
  }
  return out;
}

DialogueStep DialogueManager::Fire(const Enabled& enabled, DialogueTurn& turn) {
  const Machine& m = dialogue_.machines[enabled.machine];
  const Transition& t = m.transitions[enabled.transition];
  Running& run = running_[enabled.machine];
  DialogueStep step{m.name, m.states[t.from], m.states[t.to], t.Hears(), {}, {}};
  for (const Action& a : t.actions) {
    switch (a.kind) {
      case Action::Kind::kSay: step.said.push_back(Fill(a.text, enabled.captures)); break;
      case Action::Kind::kEmotionalInfluence: emotions_.Influence(a.emotion, a.value); break;
      case Action::Kind::kGesture: step.gestures.push_back(a.text); break;
      case Action::Kind::kSet: {
        const auto it = std::find_if(dialogue_.variables.begin(), dialogue_.variables.end(),
                                     [&](const dialogue::Variable& v) { return v.name == a.variable; });
        values_[static_cast<std::size_t>(it - dialogue_.variables.begin())] = Fill(a.text, enabled.captures);
        break;
      }
      case Action::Kind::kEnd: turn.ended = ended_ = true; break;
    }
  }
  run.state = t.to;
  run.seconds_in_state = 0;
  if (m.final[t.to]) {
    if (m.cyclic) run.state = m.start;
    else run.finished = true;
  }
  return step;
}

DialogueTurn DialogueManager::Update(const DialogueInput& input) {
  if (!(input.dt_s >= 0) || !std::isfinite(input.dt_s))
    throw DialogueError(dialogue_.file + ": a dialogue update's time step must be a finite number of at least 0 seconds");
  DialogueTurn turn;
  if (ended_) return turn;
  emotions_.Decay(input.dt_s);
  for (Running& run : running_) run.seconds_in_state += input.dt_s;
  bool heard_available = input.heard.has_value();
  for (int made = 0; !ended_; ++made) {
    // W: the enabled machines of the highest priority.
    std::vector<Enabled> w;
    for (std::size_t m = 0; m < dialogue_.machines.size(); ++m) {
      std::optional<Enabled> enabled = FirstEnabled(m, input, heard_available);
      if (!enabled) continue;
      const int priority = dialogue_.machines[m].priority;
      if (!w.empty() && priority < dialogue_.machines[w.front().machine].priority) continue;
      if (!w.empty() && priority > dialogue_.machines[w.front().machine].priority) w.clear();
      w.push_back(std::move(*enabled));
    }
    if (w.empty()) break;
    if (selected_ && dialogue_.machines[*selected_].strong) {
      std::optional<Enabled> keeps = FirstEnabled(*selected_, input, heard_available);
      if (keeps) w = {std::move(*keeps)};
    }
    if (made == kMaxTransitionsPerUpdate) {
      const Machine& m = dialogue_.machines[w.front().machine];
      throw DialogueError(dialogue_.file + ": machine '" + m.name + "', state '" + m.states[running_[w.front().machine].state] +
                          "': " + std::to_string(kMaxTransitionsPerUpdate) +
                          " transitions in one update without waiting for anything (a cycle through variables or emotions)");
    }
    const std::size_t chosen = w.size() == 1 ? 0 : std::uniform_int_distribution<std::size_t>(0, w.size() - 1)(random_);
    selected_ = w[chosen].machine;
    DialogueStep step = Fire(w[chosen], turn);
    if (step.took_heard) {
      heard_available = false;
      turn.heard_taken = true;
    }
    turn.steps.push_back(std::move(step));
  }
  return turn;
}

std::vector<std::string> DialogueManager::ExpectedPhrases() const {
  std::vector<std::string> phrases;
  if (ended_) return phrases;
  std::vector<std::size_t> order(dialogue_.machines.size());
  for (std::size_t m = 0; m < order.size(); ++m) order[m] = m;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return dialogue_.machines[a].priority > dialogue_.machines[b].priority;
  });
  for (const std::size_t m : order) {
    if (running_[m].finished) continue;
    for (const Transition& t : dialogue_.machines[m].transitions) {
      if (t.from != running_[m].state) continue;
      for (const Condition& c : t.conditions)
        for (const Pattern& p : c.patterns)
          if (std::find(phrases.begin(), phrases.end(), p.text()) == phrases.end()) phrases.push_back(p.text());
    }
  }
  return phrases;
}

std::string DialogueManager::SelectedMachine() const {
  return selected_ ? dialogue_.machines[*selected_].name : std::string();
}

std::string DialogueManager::StateOf(std::string_view machine) const {
  for (std::size_t m = 0; m < dialogue_.machines.size(); ++m)
    if (dialogue_.machines[m].name == machine) return dialogue_.machines[m].states[running_[m].state];
  return {};
}

bool DialogueManager::Finished(std::string_view machine) const {
  for (std::size_t m = 0; m < dialogue_.machines.size(); ++m)
    if (dialogue_.machines[m].name == machine) return running_[m].finished;
  return false;
}

std::optional<std::string> DialogueManager::Variable(std::string_view name) const {
  for (std::size_t v = 0; v < dialogue_.variables.size(); ++v)
    if (dialogue_.variables[v].name == name) return values_[v];
  return std::nullopt;
}

}  // namespace arview::dialogue
