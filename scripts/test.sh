#!/usr/bin/env bash
# The README's test command: installs the Debian packages, builds the release preset and runs
# every test with ctest (which prints its summary line). Pass --asan to use the AddressSanitizer
# preset (every test), --tsan for the ThreadSanitizer preset: it builds the binaries that hold
# the tests labelled `tsan` (the ones that run threads of ours) and runs those, with the
# suppressions of tests/tsan.supp (docs/reliability.md, "Round 4: sanitizers").
# A one-node Slurm cluster (scripts/slurm-local.sh) runs during ctest for the tests labelled
# `slurm`, and is stopped after them (unless it was running before).
set -euo pipefail
cd "$(dirname "$0")/.."
preset=release
case "${1:-}" in
  --asan) preset=asan ;;
  --tsan) preset=tsan ;;
  "") ;;
  *) echo "usage: scripts/test.sh [--asan | --tsan]" >&2; exit 2 ;;
esac
bash scripts/install-deps.sh
# The presets say 2 jobs (this project's own machines have 2 cores); a bigger machine builds with
# all its cores and runs up to 4 tests at once (more would crowd the tests that time threads).
cores=$(nproc)
test_jobs=$(( cores < 4 ? (cores < 2 ? 2 : cores) : 4 ))
cmake --preset "$preset"
cmake --build --preset "$preset" -j "$cores"
export SLURM_CONF="$(bash scripts/slurm-local.sh conf)"
if ! bash scripts/slurm-local.sh status >/dev/null 2>&1; then
  if bash scripts/slurm-local.sh start; then
    trap 'bash scripts/slurm-local.sh stop' EXIT
  else
    echo "test.sh: Slurm did not start: the tests labelled slurm skip (fail with ARVIEW_REQUIRE_DATA=1)" >&2
  fi
fi
if [ "$preset" = tsan ]; then
  ctest --preset tsan -L tsan -j "$test_jobs"
else
  ctest --preset "$preset" -j "$test_jobs"
fi
