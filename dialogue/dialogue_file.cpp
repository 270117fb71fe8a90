#include "dialogue/dialogue_file.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <functional>
#include <set>
#include <sstream>

#include "base/input_guard.h"
#include "base/library_errors.h"

namespace arview::dialogue {
namespace {

// Where a message points: the file and line, and the machine and state when inside one.
struct Place {
  const std::string* file = nullptr;
  std::string machine;
  std::string state;

  std::string At(const YAML::Node& node) const { return At(node.Mark().line + 1); }
  std::string At(int line) const {
    std::string where = *file + ":" + std::to_string(line) + ": ";
    if (!machine.empty()) where += "machine '" + machine + "'";
    if (!state.empty()) where += ", state '" + state + "'";
    if (!machine.empty()) where += ": ";
    return where;
  }
  [[noreturn]] void Fail(const YAML::Node& node, const std::string& what) const { throw DialogueError(At(node) + what); }
  [[noreturn]] void Fail(int line, const std::string& what) const { throw DialogueError(At(line) + what); }
};

// Anchors, aliases and tags are refused before the tree is built: an alias can expand a small
// file into an exponentially large tree, and no dialogue needs them.
class NoAliases : public YAML::EventHandler {
 public:
  explicit NoAliases(const std::string& file) : file_(file) {}
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { Check(mark, "", anchor); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { Refuse(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor, const std::string&) override {
    Check(mark, tag, anchor);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    Check(mark, tag, anchor);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    Check(mark, tag, anchor);
  }
  void OnMapEnd() override {}

 private:
  void Check(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor) const {
    if (anchor != YAML::NullAnchor || (!tag.empty() && tag != "?" && tag != "!")) Refuse(mark);
  }
  [[noreturn]] void Refuse(const YAML::Mark& mark) const {
    throw DialogueError(file_ + ":" + std::to_string(mark.line + 1) + ": anchors, aliases and tags are not supported");
  }
  const std::string& file_;
};

YAML::Node ParseYaml(std::string_view text, const std::string& file) {
  try {
    RequireYamlDepthAtMost(text, kMaxYamlDepth, file);
  } catch (const InputError& e) {  // a refusal of the file, as every other: the loader's own type
    throw DialogueError(e.what());
  }
  const std::string copy(text);
  try {
    std::istringstream events(copy);
    YAML::Parser parser(events);
    NoAliases no_aliases(file);
    parser.HandleNextDocument(no_aliases);
    if (parser.HandleNextDocument(no_aliases)) throw DialogueError(file + ": only one YAML document is supported");
    return YAML::Load(copy);
  } catch (const YAML::Exception& e) {
    throw DialogueError(file + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

std::string Scalar(const YAML::Node& node, const Place& place, const std::string& what) {
  if (!node.IsScalar()) place.Fail(node, what + " must be a single value");
  return node.Scalar();
}

double Number(const YAML::Node& node, const Place& place, const std::string& what) {
  const std::string text = Scalar(node, place, what);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    place.Fail(node, what + " '" + text.substr(0, 40) + "' is not a number");
  return value;
}

double UnitNumber(const YAML::Node& node, const Place& place, const std::string& what) {
  const double value = Number(node, place, what);
  if (value < 0 || value > 1) place.Fail(node, what + " " + Scalar(node, place, what) + " is outside [0, 1]");
  return value;
}

double NonNegative(const YAML::Node& node, const Place& place, const std::string& what) {
  const double value = Number(node, place, what);
  if (value < 0) place.Fail(node, what + " " + Scalar(node, place, what) + " is negative");
  return value;
}

bool Flag(const YAML::Node& node, const Place& place, const std::string& what) {
  const std::string text = Scalar(node, place, what);
  if (text == "true") return true;
  if (text == "false") return false;
  place.Fail(node, what + " '" + text.substr(0, 40) + "' is not true or false");
}

// A name: a machine's, a state's, a variable's. Letters, digits, '_' and '-'.
std::string Name(const YAML::Node& node, const Place& place, const std::string& what) {
  const std::string text = Scalar(node, place, what);
  const bool ok = !text.empty() && text.size() <= 64 && std::all_of(text.begin(), text.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
  if (!ok) place.Fail(node, what + " '" + text.substr(0, 40) + "' is not a name (letters, digits, '_', '-'; at most 64)");
  return text;
}

template <typename E>
E Named(const YAML::Node& node, const Place& place, const std::string& what) {
  const std::string text = Scalar(node, place, what);
  if (const auto value = EnumFromString<E>(text)) return *value;
  place.Fail(node, "unknown " + what + " '" + text.substr(0, 40) + "' (one of " + EnumNameList<E>() + ")");
}

// A mapping whose keys are among `allowed` (each once), as (key, value) pairs in file order.
std::vector<std::pair<std::string, YAML::Node>> Entries(const YAML::Node& node, const Place& place,
                                                         const std::string& what,
                                                         std::initializer_list<std::string_view> allowed) {
  if (!node.IsMap()) place.Fail(node, what + " must be a mapping");
  std::vector<std::pair<std::string, YAML::Node>> entries;
  std::set<std::string> seen;
  for (const auto& entry : node) {
    const std::string key = Scalar(entry.first, place, "a key");
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      place.Fail(entry.first, "unknown key '" + key.substr(0, 40) + "' in " + what + " (one of " + list + ")");
    }
    if (!seen.insert(key).second) place.Fail(entry.first, "'" + key + "' is given twice in " + what);
    entries.emplace_back(key, entry.second);
  }
  return entries;
}

YAML::Node Required(const std::vector<std::pair<std::string, YAML::Node>>& entries, const YAML::Node& parent,
                    const Place& place, const std::string& key, const std::string& what) {
  for (const auto& [k, v] : entries)
    if (k == key) return v;
  place.Fail(parent, what + " has no '" + key + "'");
}

std::vector<YAML::Node> Items(const YAML::Node& node, const Place& place, const std::string& what) {
  if (node.IsNull()) return {};
  if (!node.IsSequence()) place.Fail(node, what + " must be a list");
  return std::vector<YAML::Node>(node.begin(), node.end());
}

// A single-key mapping (`- heard: "..."`), or a bare word for the actions that take no value.
std::pair<std::string, YAML::Node> OneKey(const YAML::Node& item, const Place& place, const std::string& what) {
  if (item.IsScalar()) return {item.Scalar(), YAML::Node()};
  if (!item.IsMap() || item.size() != 1) place.Fail(item, what + " must be one key and its value");
  const auto entry = *item.begin();
  return {Scalar(entry.first, place, "a key"), entry.second};
}

// ---------------------------------------------------------------------------------------------

struct Reader {
  Dialogue d;
  Place place;
  // Set by CheckDialogueFile: undefined names are listed here, every one, instead of thrown; a
  // transition whose `from` or `to` is undefined is then left out of the dialogue.
  std::vector<CheckFinding>* undefined_names = nullptr;

  void Undefined(const YAML::Node& node, const std::string& what) const {
    if (!undefined_names) place.Fail(node, what);
    undefined_names->push_back({place.machine, place.state, place.At(node) + what, true});
  }

  const Variable* FindVariable(const std::string& name) const {
    for (const Variable& v : d.variables)
      if (v.name == name) return &v;
    return nullptr;
  }

  void RequireVariable(const YAML::Node& node, const std::string& name) const {
    if (!FindVariable(name)) Undefined(node, "variable '" + name + "' is not defined (under 'variables:')");
  }

  // $1..$9 within the transition's captures, ${name} a defined variable, $$ a dollar.
  void CheckReferences(const YAML::Node& node, const std::string& text, std::size_t captures) const {
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] != '$') continue;
      const char next = i + 1 < text.size() ? text[i + 1] : '\0';
      if (next == '$') {
        ++i;
      } else if (next >= '1' && next <= '9') {
        const std::size_t n = static_cast<std::size_t>(next - '0');
        if (n > captures)
          Undefined(node, "$" + std::string(1, next) + " is not defined: the transition's heard patterns capture " +
                              std::to_string(captures) + " wildcard(s)");
        ++i;
      } else if (next == '{') {
        const std::size_t close = text.find('}', i);
        if (close == std::string::npos) place.Fail(node, "'${' without its '}'");
        RequireVariable(node, text.substr(i + 2, close - i - 2));
        i = close;
      } else {
        place.Fail(node, "a '$' must start $1..$9, ${variable} or $$ (a dollar sign)");
      }
    }
  }

  void ReadHeader(const YAML::Node& root) {
    const auto entries = Entries(root, place, "the dialogue", {"dialogue", "personality", "decay", "variables", "machines"});
    const YAML::Node version = Required(entries, root, place, "dialogue", "the dialogue");
    if (Scalar(version, place, "dialogue") != std::to_string(kDialogueFormatVersion))
      place.Fail(version, "dialogue format " + version.Scalar().substr(0, 20) + " is not one this arview reads (" +
                              std::to_string(kDialogueFormatVersion) + ")");
    const YAML::Node personality = Required(entries, root, place, "personality", "the dialogue");
    for (const auto& [trait, value] : Entries(personality, place, "personality",
                                              {"openness", "conscientiousness", "extraversion", "agreeableness", "neuroticism"}))
      d.personality[static_cast<std::size_t>(*EnumFromString<Trait>(trait))] = UnitNumber(value, place, trait);
    if (personality.size() != kTraitCount)
      place.Fail(personality, "personality needs all five traits: " + EnumNameList<Trait>());
    d.decay_per_s = NonNegative(Required(entries, root, place, "decay", "the dialogue"), place, "decay");
    for (const auto& [key, value] : entries) {
      if (key != "variables") continue;
      if (!value.IsMap() && !value.IsNull()) place.Fail(value, "variables must be a mapping of names to initial values");
      for (const auto& entry : value) {
        const std::string name = Name(entry.first, place, "a variable");
        if (FindVariable(name)) place.Fail(entry.first, "variable '" + name + "' is given twice");
        d.variables.push_back({name, entry.second.IsNull() ? "" : Scalar(entry.second, place, "variable '" + name + "'")});
      }
    }
  }

  std::vector<Pattern> Patterns(const YAML::Node& node) const {
    std::vector<Pattern> patterns;
    const std::string origin = place.At(node) + "heard";
    if (node.IsScalar()) {
      patterns.push_back(Pattern::Compile(node.Scalar(), origin));
    } else {
      for (const YAML::Node& item : Items(node, place, "heard")) patterns.push_back(Pattern::Compile(Scalar(item, place, "a pattern"), origin));
      if (patterns.empty()) place.Fail(node, "heard has no pattern");
    }
    return patterns;
  }

  Condition ReadCondition(const YAML::Node& item) const {
    const auto [key, value] = OneKey(item, place, "a condition");
    Condition c;
    c.line = item.Mark().line + 1;
    auto threshold = [&](Condition::Kind kind) {
      c.kind = kind;
      const auto entries = Entries(value, place, key, {"emotion", "value"});
      c.emotion = Named<Emotion>(Required(entries, value, place, "emotion", key), place, "emotion");
      c.value = UnitNumber(Required(entries, value, place, "value", key), place, key + "'s value");
    };
    if (key == "heard") {
      c.kind = Condition::Kind::kHeard;
      c.patterns = Patterns(value);
    } else if (key == "above_threshold") {
      threshold(Condition::Kind::kAboveThreshold);
    } else if (key == "below_threshold") {
      threshold(Condition::Kind::kBelowThreshold);
    } else if (key == "variable") {
      const auto entries = Entries(value, place, key, {"name", "equals", "not_equals"});
      c.variable = Name(Required(entries, value, place, "name", key), place, "a variable");
      RequireVariable(value, c.variable);
      if (entries.size() != 2) place.Fail(value, "variable needs its name and one of equals or not_equals");
      const auto& [test, text] = entries[0].first == "name" ? entries[1] : entries[0];
      c.kind = test == "equals" ? Condition::Kind::kVariableEquals : Condition::Kind::kVariableDiffers;
      c.text = text.IsNull() ? "" : Scalar(text, place, test);
    } else if (key == "in_state_longer_than") {
      c.kind = Condition::Kind::kInStateLongerThan;
      c.value = NonNegative(value, place, key);
    } else if (key == "viewer_closer_than" || key == "viewer_farther_than") {
      c.kind = key == "viewer_closer_than" ? Condition::Kind::kViewerCloserThan : Condition::Kind::kViewerFartherThan;
      c.value = NonNegative(value, place, key);
    } else if (key == "viewer_side") {
      c.kind = Condition::Kind::kViewerSide;
      c.side = Named<Side>(value, place, "viewer side");
    } else if (key == "viewer_gaze" || key == "viewer_tracked") {
      c.kind = key == "viewer_gaze" ? Condition::Kind::kViewerGaze : Condition::Kind::kViewerTracked;
      c.flag = Flag(value, place, key);
    } else {
      place.Fail(item, "unknown condition '" + key.substr(0, 40) +
                           "' (one of heard, above_threshold, below_threshold, variable, in_state_longer_than, "
                           "viewer_closer_than, viewer_farther_than, viewer_side, viewer_gaze, viewer_tracked)");
    }
    return c;
  }

  Action ReadAction(const YAML::Node& item, std::size_t captures) const {
    const auto [key, value] = OneKey(item, place, "an action");
    Action a;
    a.line = item.Mark().line + 1;
    if (key == "end") {
      if (!item.IsScalar()) place.Fail(item, "end takes no value: write '- end'");
      a.kind = Action::Kind::kEnd;
    } else if (item.IsScalar()) {
      place.Fail(item, "unknown action '" + key.substr(0, 40) + "' (one of say, emotional_influence, gesture, set, end)");
    } else if (key == "say") {
      a.kind = Action::Kind::kSay;
      a.text = Scalar(value, place, "say");
      if (a.text.empty()) place.Fail(value, "say has no text");
      CheckReferences(value, a.text, captures);
    } else if (key == "emotional_influence") {
      a.kind = Action::Kind::kEmotionalInfluence;
      const auto entries = Entries(value, place, key, {"emotion", "value"});
      a.emotion = Named<Emotion>(Required(entries, value, place, "emotion", key), place, "emotion");
      a.value = UnitNumber(Required(entries, value, place, "value", key), place, "emotional_influence's value");
    } else if (key == "gesture") {
      a.kind = Action::Kind::kGesture;
      a.text = Name(value, place, "a gesture");
    } else if (key == "set") {
      a.kind = Action::Kind::kSet;
      const auto entries = Entries(value, place, key, {"name", "value"});
      a.variable = Name(Required(entries, value, place, "name", key), place, "a variable");
      RequireVariable(value, a.variable);
      const YAML::Node text = Required(entries, value, place, "value", key);
      a.text = text.IsNull() ? "" : Scalar(text, place, "set's value");
      CheckReferences(text, a.text, captures);
    } else {
      place.Fail(item, "unknown action '" + key.substr(0, 40) + "' (one of say, emotional_influence, gesture, set, end)");
    }
    return a;
  }

  // Nothing when the state is not defined (and the reader collects undefined names).
  std::optional<std::size_t> StateIndex(const Machine& m, const YAML::Node& node, const std::string& what) const {
    const std::string name = Name(node, place, what);
    const auto it = std::find(m.states.begin(), m.states.end(), name);
    if (it != m.states.end()) return static_cast<std::size_t>(it - m.states.begin());
    Undefined(node, what + " '" + name + "' is not one of the machine's states");
    return std::nullopt;
  }

  // Nothing when its `from` or `to` is not defined (and the reader collects undefined names).
  std::optional<Transition> ReadTransition(Machine& m, const YAML::Node& node) {
    place.state.clear();
    const auto entries = Entries(node, place, "a transition", {"from", "to", "when", "do"});
    Transition t;
    t.line = node.Mark().line + 1;
    const std::optional<std::size_t> from = StateIndex(m, Required(entries, node, place, "from", "a transition"), "from");
    if (from) place.state = m.states[*from];
    const std::optional<std::size_t> to = StateIndex(m, Required(entries, node, place, "to", "a transition"), "to");
    for (const auto& [key, value] : entries)
      if (key == "when")
        for (const YAML::Node& item : Items(value, place, "when")) t.conditions.push_back(ReadCondition(item));
    for (const auto& [key, value] : entries)
      if (key == "do")
        for (const YAML::Node& item : Items(value, place, "do")) t.actions.push_back(ReadAction(item, t.Captures()));
    if (std::count_if(t.conditions.begin(), t.conditions.end(), [](const Condition& c) { return c.kind == Condition::Kind::kHeard; }) > 1)
      place.Fail(node, "a transition hears once: put the patterns in one heard list");
    if (!from || !to) return std::nullopt;
    t.from = *from;
    t.to = *to;
    return t;
  }

  void ReadMachine(const YAML::Node& node) {
    place.state.clear();
    // The name as written, for the messages about the machine's other keys.
    const YAML::Node written_name = node.IsMap() ? node["name"] : YAML::Node();
    place.machine = written_name && written_name.IsScalar() ? written_name.Scalar().substr(0, 64) : std::string();
    const auto entries = Entries(node, place, "a machine",
                                 {"name", "priority", "cyclic", "strong", "states", "start", "final", "transitions"});
    Machine m;
    m.line = node.Mark().line + 1;
    place.machine.clear();
    m.name = Name(Required(entries, node, place, "name", "a machine"), place, "a machine's name");
    for (const Machine& other : d.machines)
      if (other.name == m.name) place.Fail(node, "machine '" + m.name + "' is given twice");
    place.machine = m.name;
    for (const YAML::Node& state : Items(Required(entries, node, place, "states", "the machine"), place, "states")) {
      const std::string name = Name(state, place, "a state");
      if (std::find(m.states.begin(), m.states.end(), name) != m.states.end()) place.Fail(state, "state '" + name + "' is given twice");
      m.states.push_back(name);
    }
    if (m.states.empty()) place.Fail(node, "the machine has no states");
    m.final.assign(m.states.size(), false);
    for (const auto& [key, value] : entries) {
      if (key == "priority") {
        const double p = NonNegative(value, place, "priority");
        if (p != std::floor(p) || p > 1e6) place.Fail(value, "priority must be a whole number from 0 to 1000000");
        m.priority = static_cast<int>(p);
      } else if (key == "cyclic") {
        m.cyclic = Flag(value, place, "cyclic");
      } else if (key == "strong") {
        m.strong = Flag(value, place, "strong");
      } else if (key == "start") {
        m.start = StateIndex(m, value, "start").value_or(m.start);
      } else if (key == "final") {
        for (const YAML::Node& state : Items(value, place, "final"))
          if (const std::optional<std::size_t> s = StateIndex(m, state, "final state")) m.final[*s] = true;
      }
    }
    if (m.final[m.start]) place.Fail(node, "the start state '" + m.states[m.start] + "' cannot be final");
    for (const auto& [key, value] : entries)
      if (key == "transitions")
        for (const YAML::Node& item : Items(value, place, "transitions"))
          if (std::optional<Transition> t = ReadTransition(m, item)) m.transitions.push_back(std::move(*t));
    for (const Transition& t : m.transitions)
      if (m.final[t.from])
        place.Fail(t.line, "machine '" + m.name + "': final state '" + m.states[t.from] +
                               "' has a transition out of it, which would never fire");
    d.machines.push_back(std::move(m));
  }
};

// The viewer's situations that the machine's conditions tell apart: tracked or not, each side,
// gaze or not, and a distance in each interval its distance thresholds make (at and between
// them). Within one update the viewer does not move, so these are all the cases to try.
std::vector<ViewerInput> ViewerSituations(const Machine& m) {
  std::vector<double> thresholds;
  for (const Transition& t : m.transitions) {
    const bool viewer_only = std::all_of(t.conditions.begin(), t.conditions.end(), [](const Condition& c) {
      return ViewerConditionHolds(c, ViewerInput{}).has_value();
    });
    if (!viewer_only) continue;  // never fires twice in an update on the viewer alone
    for (const Condition& c : t.conditions)
      if (c.kind == Condition::Kind::kViewerCloserThan || c.kind == Condition::Kind::kViewerFartherThan) thresholds.push_back(c.value);
  }
  std::sort(thresholds.begin(), thresholds.end());
  thresholds.erase(std::unique(thresholds.begin(), thresholds.end()), thresholds.end());
  std::vector<double> distances{0.0};
  for (std::size_t i = 0; i < thresholds.size(); ++i) {
    distances.push_back(thresholds[i]);
    distances.push_back(i + 1 < thresholds.size() ? (thresholds[i] + thresholds[i + 1]) / 2 : thresholds[i] + 1);
  }
  std::vector<ViewerInput> situations{{false, 0.0, true, false}};
  for (const double distance : distances)
    for (const bool in_front : {true, false})
      for (const bool gaze : {true, false}) situations.push_back({true, distance, in_front, gaze});
  return situations;
}

std::string Describe(const ViewerInput& v) {
  if (!v.tracked) return "while the viewer is lost";
  char distance[32];
  std::snprintf(distance, sizeof distance, "%g", v.distance_m);
  return std::string("while the viewer is ") + distance + " away, " + (v.in_front ? "in front" : "behind") + ", " +
         (v.gaze_on_character ? "looking at the character" : "looking away");
}

// A cycle of transitions that can all fire in `viewer`'s situation without anything else
// changing: no heard text (taken once an update), no time in a state (0 after a transition), no
// emotion or variable (an action on the way may change them; the manager's step limit catches
// those). A cyclic machine's final states lead back to its start.
std::vector<std::size_t> CycleWaitingOnlyOnTheViewer(const Machine& m, const ViewerInput& viewer) {
  const std::size_t n = m.states.size();
  std::vector<std::vector<std::size_t>> next(n);
  for (const Transition& t : m.transitions) {
    const bool fires = std::all_of(t.conditions.begin(), t.conditions.end(), [&](const Condition& c) {
      return ViewerConditionHolds(c, viewer).value_or(false);
    });
    if (fires) next[t.from].push_back(t.to);
  }
  if (m.cyclic)
    for (std::size_t s = 0; s < n; ++s)
      if (m.final[s]) next[s].push_back(m.start);
  std::vector<int> mark(n, 0);  // 0 unseen, 1 on the path, 2 done
  std::vector<std::size_t> path;
  std::vector<std::size_t> cycle;
  std::function<bool(std::size_t)> visit = [&](std::size_t s) {
    mark[s] = 1;
    path.push_back(s);
    for (const std::size_t to : next[s]) {
      if (mark[to] == 1) {
        cycle.assign(std::find(path.begin(), path.end(), to), path.end());
        cycle.push_back(to);
        return true;
      }
      if (mark[to] == 0 && visit(to)) return true;
    }
    path.pop_back();
    mark[s] = 2;
    return false;
  };
  for (std::size_t s = 0; s < n; ++s)
    if (mark[s] == 0 && visit(s)) return cycle;
  return {};
}

void RefuseEndlessCycles(const Dialogue& d) {
  for (const Machine& m : d.machines) {
    for (const ViewerInput& viewer : ViewerSituations(m)) {
      const std::vector<std::size_t> cycle = CycleWaitingOnlyOnTheViewer(m, viewer);
      if (cycle.empty()) continue;
      bool viewer_conditions = false;
      std::string states;
      for (std::size_t i = 0; i < cycle.size(); ++i) {
        states += (i ? " -> " : "") + m.states[cycle[i]];
        for (const Transition& t : m.transitions)
          if (i + 1 < cycle.size() && t.from == cycle[i] && t.to == cycle[i + 1]) viewer_conditions = viewer_conditions || !t.conditions.empty();
      }
      const std::string what = viewer_conditions ? " is a cycle of transitions that wait only on the viewer: " + Describe(viewer) + ","
                                                 : " is a cycle of transitions without a condition:";
      throw DialogueError(d.file + ":" + std::to_string(m.line) + ": machine '" + m.name + "', state '" +
                          m.states[cycle.front()] + "': " + states + (m.cyclic ? " (a final state restarts it)" : "") + what +
                          (m.strong ? " the strong machine would never release the conversation"
                                    : " the machine would never wait for anything"));
    }
  }
}

}  // namespace

std::optional<bool> ViewerConditionHolds(const Condition& c, const ViewerInput& viewer) {
  switch (c.kind) {
    case Condition::Kind::kViewerCloserThan: return viewer.tracked && viewer.distance_m < c.value;
    case Condition::Kind::kViewerFartherThan: return viewer.tracked && viewer.distance_m > c.value;
    case Condition::Kind::kViewerSide: return viewer.tracked && viewer.in_front == (c.side == Side::kFront);
    case Condition::Kind::kViewerGaze: return viewer.tracked && viewer.gaze_on_character == c.flag;
    case Condition::Kind::kViewerTracked: return viewer.tracked == c.flag;
    default: return std::nullopt;
  }
}

std::size_t Transition::Captures() const {
  std::optional<std::size_t> fewest;
  for (const Condition& c : conditions)
    for (const Pattern& p : c.patterns) fewest = std::min(fewest.value_or(p.wildcards()), p.wildcards());
  return fewest.value_or(0);
}

bool Transition::Hears() const {
  return std::any_of(conditions.begin(), conditions.end(), [](const Condition& c) { return c.kind == Condition::Kind::kHeard; });
}

namespace {

Dialogue Read(std::string_view text, const std::string& file, std::vector<CheckFinding>* undefined_names) {
  return NamingInput<DialogueError>(file, [&] {
    if (text.size() > kMaxDialogueFileBytes)
      throw DialogueError(file + ": " + std::to_string(text.size()) + " bytes; dialogue files are limited to " +
                          std::to_string(kMaxDialogueFileBytes));
    const YAML::Node root = ParseYaml(text, file);
    Reader reader;
    reader.undefined_names = undefined_names;
    reader.d.file = file;
    reader.place.file = &reader.d.file;
    if (!root.IsMap()) throw DialogueError(file + ": not a dialogue file (a mapping with dialogue: " +
                                           std::to_string(kDialogueFormatVersion) + ", personality, decay and machines)");
    reader.ReadHeader(root);
    const YAML::Node machines = root["machines"];
    if (!machines) throw DialogueError(file + ": the dialogue has no 'machines'");
    for (const YAML::Node& item : Items(machines, reader.place, "machines")) reader.ReadMachine(item);
    if (reader.d.machines.empty()) throw DialogueError(file + ": the dialogue has no machines");
    RefuseEndlessCycles(reader.d);
    return std::move(reader.d);
  });
}

}  // namespace

Dialogue ParseDialogue(std::string_view text, const std::string& file) { return Read(text, file, nullptr); }

Dialogue LoadDialogue(const std::filesystem::path& path) {
  return NamingInput<DialogueError>(path.string(), [&] {
    return ParseDialogue(ReadFileUpTo(path, kMaxDialogueFileBytes), path.string());
  });
}

std::vector<CheckFinding> CheckDialogue(const Dialogue& d) {
  std::vector<CheckFinding> findings;
  for (const Machine& m : d.machines) {
    std::vector<bool> reached(m.states.size(), false);
    std::vector<std::size_t> todo{m.start};
    reached[m.start] = true;
    while (!todo.empty()) {
      const std::size_t s = todo.back();
      todo.pop_back();
      for (const Transition& t : m.transitions)
        if (t.from == s && !reached[t.to]) {
          reached[t.to] = true;
          todo.push_back(t.to);
        }
    }
    for (std::size_t s = 0; s < m.states.size(); ++s)
      if (!reached[s])
        findings.push_back({m.name, m.states[s],
                            d.file + ":" + std::to_string(m.line) + ": machine '" + m.name + "', state '" + m.states[s] +
                                "': unreachable: no transition from the start state '" + m.states[m.start] + "' leads to it"});
  }
  for (const Variable& v : d.variables) {
    bool used = false;
    for (const Machine& m : d.machines)
      for (const Transition& t : m.transitions) {
        for (const Condition& c : t.conditions) used = used || c.variable == v.name;
        for (const Action& a : t.actions)
          used = used || a.variable == v.name || a.text.find("${" + v.name + "}") != std::string::npos;
      }
    if (!used)
      findings.push_back({"", "", d.file + ": variable '" + v.name + "' is defined but no machine reads or sets it", false});
  }
  return findings;
}

std::vector<CheckFinding> CheckDialogueFile(const std::filesystem::path& path) {
  std::vector<CheckFinding> findings;
  const Dialogue d = NamingInput<DialogueError>(path.string(), [&] {
    return Read(ReadFileUpTo(path, kMaxDialogueFileBytes), path.string(), &findings);
  });
  // With a transition left out, a state it leads to would be named unreachable for no reason.
  if (!findings.empty()) return findings;
  return CheckDialogue(d);
}

}  // namespace arview::dialogue
