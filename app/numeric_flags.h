#pragma once
// Numbers on the command line are checked before CLI11 converts them: CLI11's range checks let
// NaN through (every comparison with NaN is false), and its unsigned conversion wraps a
// negative value (--seed -1 became 18446744073709551615).

#include <CLI/CLI.hpp>

namespace arview::app {

// Adds to every floating-point option of `app` and its subcommands a check that the value is
// a finite number of at most 1e12 in magnitude, and to every unsigned one a check that it is
// not negative. Call once, after every command is registered.
void GuardNumericOptions(CLI::App& app);

}  // namespace arview::app
