#pragma once
// Shared by the dialogue tests: a small valid dialogue to vary, and the demo's path.

#include <cstdlib>
#include <filesystem>
#include <string>

namespace arview::dialogue::testing {

// The header every test dialogue starts with.
inline std::string Header(const std::string& variables = "") {
  return "dialogue: 1\n"
         "personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, agreeableness: 0.5, neuroticism: 0.5}\n"
         "decay: 0.1\n" +
         (variables.empty() ? std::string() : "variables: {" + variables + "}\n") + "machines:\n";
}

inline std::filesystem::path ExampleDialogue() {
  const char* source = std::getenv("ARVIEW_SOURCE_DIR");
  return std::filesystem::path(source ? source : ".") / "docs/examples/guide-dialogue.yaml";
}

}  // namespace arview::dialogue::testing
