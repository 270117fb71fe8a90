#pragma once
// Numbers on the command line are checked before CLI11 converts them: CLI11's range checks let
// NaN through (every comparison with NaN is false), and its unsigned conversion wraps a
// negative value (--seed -1 became 18446744073709551615).

#include <CLI/CLI.hpp>
#include <opencv2/core/types.hpp>

#include <optional>
#include <string>

namespace arview::app {

// Adds to every floating-point option of `app` and its subcommands a check that the value is
// a finite number of at most 1e12 in magnitude, to every unsigned one a check that it is not
// negative, and to every numeric one a check that it is not empty. Call once, after every
// command is registered.
void GuardNumericOptions(CLI::App& app);

// A frame size written WIDTHxHEIGHT (digits only, `x` or `X`), as every command's --size takes
// it; nullopt for anything else (signs, spaces, a trailing character, more than 5 digits).
std::optional<cv::Size> ParseFrameSize(const std::string& text);

// The --size check of a command: WIDTHxHEIGHT within [smallest, largest] in both dimensions.
// CLI11 reports its message as "--size: ..." with the usage exit status.
CLI::Validator FrameSizeCheck(cv::Size smallest, cv::Size largest);

// A number of seconds where -1 means never: -1 or at least 0 (-0.5 read as never, undocumented).
CLI::Validator NeverOrNotNegative();

// A chessboard's inner corners written COLUMNSxROWS (as --size), each 2..99: --board's check on
// `synth room` and `map`.
CLI::Validator BoardSizeCheck();

}  // namespace arview::app
