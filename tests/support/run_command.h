#pragma once
// Runs the arview binary (path from ARVIEW_BIN, set by ctest) and captures its output, for
// end-to-end tests of the command line.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace arview::testing {

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += "'\\''"; else q += c;
  }
  return q + "'";
}

inline std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `stdin_path`: what the command reads as its standard input (a script for `dialogue chat`).
inline CommandResult RunArview(const std::vector<std::string>& args, const std::string& stdin_path = "/dev/null") {
  const char* bin = std::getenv("ARVIEW_BIN");
  std::string cmd = ShellQuote(bin ? bin : "arview");
  for (const std::string& a : args) cmd += " " + ShellQuote(a);
  const std::string base = "/tmp/arview_cmd_" + std::to_string(::getpid());
  cmd += " >" + base + ".out 2>" + base + ".err <" + ShellQuote(stdin_path);
  const int status = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = ReadWholeFile(base + ".out");
  r.err = ReadWholeFile(base + ".err");
  std::remove((base + ".out").c_str());
  std::remove((base + ".err").c_str());
  return r;
}

inline int LineCount(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  if (!text.empty() && text.back() != '\n') ++n;
  return n;
}

}  // namespace arview::testing
