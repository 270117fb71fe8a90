#pragma once
// Output files named on the command line, checked before the work that fills them starts: a
// name that cannot become a file was found at the end (track) or not at all (replay's --stats
// into a missing folder wrote a file of that name), and two flags naming one file lost the
// output written first.

#include <CLI/CLI.hpp>

#include <string>
#include <utility>
#include <vector>

namespace arview::app {

// The check of a flag that names one file to write (--stats, --trajectory, track's --out): not
// empty, not ending in '/', not an existing folder, in a folder that exists. CLI11 reports its
// message as "--flag: ..." with the usage exit status.
CLI::Validator OutputFileCheck();

// Throws CommandError (usage) when two of the named outputs ({flag, path}; an empty path, as for
// an output not asked for or one that is no file ('window', 'null'), left out) are one file.
void RequireDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs);

}  // namespace arview::app
