#pragma once
// Flags bound straight to the fields of a library's options struct, as COLMAP's command line
// binds to its option structs: the default a flag shows and starts from is the struct's own,
// written once. The flags' names are kept for the struct's Check(), whose message then names the
// flag the user gave ("--working-size must be ...") rather than the field.

#include <CLI/CLI.hpp>

#include <functional>
#include <map>
#include <string>

#include "app/cli/commands.h"
#include "base/option_check.h"

namespace arview::app {

// `path` as text and the field of `options` at that path, for OptionFlags::Add: the name a
// Check() reports for the field is then the field's own path, never a copy that could drift.
#define ARVIEW_OPTION_FIELD(options, path) #path, (options).path

class OptionFlags {
 public:
  // Adds `flag` to `cmd`, bound to `field` (the field at `path` in the options struct), its
  // default shown in --help.
  template <typename T>
  CLI::Option* Add(CLI::App* cmd, const std::string& flag, const std::string& path, T& field, const std::string& help) {
    Name(path, flag);
    return cmd->add_option(flag, field, help)->capture_default_str();
  }
  // `flag` sets the field at `path` (one flag for two fields, or a flag bound elsewhere).
  void Name(const std::string& path, const std::string& flag) { names_[path] = flag; }
  OptionNames names() const { return OptionNames(names_); }
  // options.Check() with these names; a bad value is the command's error with `exit_status`.
  template <typename Options>
  void Check(const Options& options, int exit_status) const {
    try {
      options.Check(names());
    } catch (const OptionError& e) {
      throw CommandError(e.what(), exit_status);  // the same line, with the command's status
    }
  }

 private:
  std::map<std::string, std::string, std::less<>> names_;
};

}  // namespace arview::app
