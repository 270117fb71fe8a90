#!/usr/bin/env bash
# Checks the standalone fuzz driver on a target with planted faults (driver_selftest_target.cpp):
# each kind of finding ends the run with a non-zero status and a FINDING line, the input is kept
# under the artifacts folder and the kept input reproduces the finding; a run without faults
# exits 0 and counts its executions; the same --seed gives the same inputs, another seed others.
#
#   driver_selftest.sh <fuzz_driver_selftest binary> <sanitized: 0|1>
set -uo pipefail
binary=$1
sanitized=$2
corpus=$(dirname "$0")/selftest_corpus
work=$(mktemp -d /tmp/arview-fuzz-selftest-XXXXXX)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect_finding <mode> <what the FINDING line says> [the sanitizer's report says] [driver options]
expect_finding() {
  local mode=$1 says=$2 report=${3:-}
  shift 2
  (($# > 0)) && shift
  local artifacts=$work/$mode
  local log=$work/$mode.log
  ARVIEW_FUZZ_SELFTEST=$mode timeout 60 "$binary" --seconds 20 --corpus "$corpus" --artifacts "$artifacts" "$@" >"$log" 2>&1
  local status=$?
  ((status != 0)) || fail "$mode: exit status 0"
  ((status != 124)) || fail "$mode: the driver did not stop by itself"
  grep -q "FINDING: $says" "$log" || { fail "$mode: no 'FINDING: $says' line"; sed 's/^/  | /' "$log" | tail -n 20; }
  grep -qE "seed [0-9]+" "$log" || fail "$mode: the run's seed is not printed"
  [[ -z $report ]] || grep -q "$report" "$log" || fail "$mode: no '$report' in the output"
  local kept
  kept=$(sed -n 's/.*: the input is saved as //p' "$log" | head -n 1)
  if [[ -z $kept || ! -f $kept ]]; then
    fail "$mode: the input is not kept ('$kept')"
    return
  fi
  cmp -s "$kept" "$corpus/seed" && fail "$mode: the kept input is the seed, not the mutated input"
  # Reproduce: the kept file alone, given to the same binary.
  ARVIEW_FUZZ_SELFTEST=$mode timeout 60 "$binary" --artifacts "$work/$mode-again" "$@" "$kept" >"$log.again" 2>&1
  local again=$?
  ((again != 0 && again != 124)) || fail "$mode: the kept input does not reproduce the finding (status $again)"
  grep -q "FINDING: $says" "$log.again" || fail "$mode: the reproduction does not report '$says'"
  echo "ok: $mode (status $status, kept $(wc -c <"$kept") bytes)"
}

expect_finding throw "an exception escaped the target: planted exception" ""
# Under the sanitizers UBSan's null check meets the write first: its report, then SIGABRT.
if [[ $sanitized == 1 ]]; then
  expect_finding segv "signal SIGABRT" "runtime error: store to null pointer"
else
  expect_finding segv "signal SIGSEGV"
fi
expect_finding abort "signal SIGABRT" ""
expect_finding hang "an input ran over 1" "" --timeout 1
if [[ $sanitized == 1 ]]; then
  expect_finding overflow "a sanitizer report" "ERROR: AddressSanitizer: heap-buffer-overflow"
  expect_finding signed "signal SIGABRT" "runtime error: signed integer overflow"
fi

# No fault: exits 0 after exactly --runs executions; the same seed gives the same inputs.
for run in a b c; do
  seed=7
  [[ $run == c ]] && seed=8
  ARVIEW_FUZZ_SELFTEST=log ARVIEW_FUZZ_SELFTEST_LOG=$work/inputs.$run "$binary" --corpus "$corpus" --seed $seed --runs 500 \
    --artifacts "$work/log" >"$work/log.$run" 2>&1 || fail "log $run: exit status $?"
done
grep -q "500 executions" "$work/log.a" || fail "log: '500 executions' not printed: $(cat "$work/log.a")"
[[ $(wc -l <"$work/inputs.a") == 500 ]] || fail "log: $(wc -l <"$work/inputs.a") inputs run, not 500"
cmp -s "$work/inputs.a" "$work/inputs.b" || fail "log: seed 7 twice gave different inputs"
cmp -s "$work/inputs.a" "$work/inputs.c" && fail "log: seeds 7 and 8 gave the same inputs"
distinct=$(cut -d' ' -f1 "$work/inputs.a" | sort -u | wc -l)
((distinct > 250)) || fail "log: only $distinct distinct inputs in 500"
echo "ok: log ($distinct distinct inputs in 500, repeatable by seed)"

((failures == 0)) || { echo "$failures failures"; exit 1; }
echo "the driver reports every planted fault"
