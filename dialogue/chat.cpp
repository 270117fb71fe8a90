#include "dialogue/chat.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

namespace arview::dialogue {
namespace {

std::string Fixed(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", value);
  return text;
}

std::optional<double> ParseSeconds(const std::string& word) {
  double value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size() || !std::isfinite(value) || value < 0) return std::nullopt;
  return value;
}

void PrintTurn(const DialogueTurn& turn, const DialogueManager& manager, std::ostream& out) {
  for (const DialogueStep& step : turn.steps) {
    for (const std::string& gesture : step.gestures) out << step.machine << ": [gesture " << gesture << "]\n";
    for (const std::string& said : step.said) out << step.machine << ": " << said << "\n";
  }
  out << StatusLine(manager) << "\n";
  if (turn.ended) out << "(the conversation has ended)\n";
}

// Applies "/viewer ..." words; returns the first word it did not understand ("" when all were).
std::string SetViewer(std::istringstream& words, ViewerInput& viewer) {
  std::string word;
  while (words >> word) {
    if (word == "front" || word == "behind") {
      viewer.in_front = word == "front";
    } else if (word == "gaze" || word == "no-gaze") {
      viewer.gaze_on_character = word == "gaze";
    } else if (word == "lost" || word == "tracked") {
      viewer.tracked = word == "tracked";
    } else if (const std::optional<double> metres = ParseSeconds(word)) {
      viewer.distance_m = *metres;
    } else {
      return word;
    }
  }
  return {};
}

}  // namespace

std::string StatusLine(const DialogueManager& manager) {
  const EmotionSummary s = manager.EmotionNow();
  const std::string machine = manager.SelectedMachine();
  std::string line = "[" + (machine.empty() ? std::string("-") : machine) + "] ";
  if (!s.dominant) return line + "neutral, activation " + Fixed(s.activation);
  return line + ToString(*s.dominant) + " " + Fixed(s.intensity) + " -> " + ToString(*s.expression) + " " +
         Fixed(s.expression_intensity) + ", activation " + Fixed(s.activation);
}

void RunChat(DialogueManager& manager, std::istream& in, std::ostream& out, const ChatOptions& options) {
  ViewerInput viewer = options.viewer;
  // What the character says before anything is heard (a greeting on a λ-transition).
  const DialogueTurn opening = manager.Update({0.0, std::nullopt, viewer});
  if (!opening.steps.empty()) PrintTurn(opening, manager, out);
  std::string line;
  while (!manager.ended()) {
    if (options.prompt) out << "> " << std::flush;
    if (!std::getline(in, line)) break;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line.front() != '/') {
      const DialogueTurn turn = manager.Update({options.seconds_per_line, line, viewer});
      if (!turn.heard_taken) out << "(no machine answers \"" << line.substr(0, 200) << "\")\n";
      PrintTurn(turn, manager, out);
      continue;
    }
    std::istringstream words(line.substr(1));
    std::string command;
    words >> command;
    if (command == "quit") break;
    if (command == "wait") {
      std::string seconds;
      words >> seconds;
      const std::optional<double> dt = ParseSeconds(seconds);
      if (!dt) {
        out << "/wait needs a number of seconds of at least 0, not '" << seconds << "'\n";
        continue;
      }
      PrintTurn(manager.Update({*dt, std::nullopt, viewer}), manager, out);
    } else if (command == "viewer") {
      const std::string unknown = SetViewer(words, viewer);
      if (!unknown.empty()) out << "/viewer does not know '" << unknown << "' (a distance in metres, front, behind, gaze, no-gaze, lost, tracked)\n";
      PrintTurn(manager.Update({0.0, std::nullopt, viewer}), manager, out);
    } else if (command == "expect") {
      for (const std::string& phrase : manager.ExpectedPhrases()) out << "  " << phrase << "\n";
    } else if (command == "emotions") {
      const EmotionVector& e = manager.emotions().Intensities();
      for (std::size_t i = 0; i < kEmotionCount; ++i)
        if (e[i] > 0) out << "  " << ToString(static_cast<Emotion>(i)) << " " << Fixed(e[i]) << "\n";
    } else {
      out << "unknown command '/" << command << "' (/wait S, /viewer ..., /expect, /emotions, /quit)\n";
    }
  }
}

}  // namespace arview::dialogue
