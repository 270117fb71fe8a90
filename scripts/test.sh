#!/usr/bin/env bash
# The README's test command: installs the Debian packages, builds the release preset and runs
# every test with ctest (which prints its summary line). Pass --asan to use the sanitizer preset.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=release
[ "${1:-}" = "--asan" ] && preset=asan
bash scripts/install-deps.sh
cmake --preset "$preset"
cmake --build --preset "$preset"
ctest --preset "$preset"
