#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, the `fuzz` preset: clang, ASan + UBSan) and runs each
# for N seconds, one process at a time; prints per target the executions, libFuzzer's
# coverage (`cov:`) and the crashes (kept under build/fuzz/crashes/<target>/).
#
#   scripts/fuzz.sh [seconds-per-target] [target...]      (default 20 s, every target)
#   scripts/fuzz.sh 300 fuzz_camera fuzz_scene
#
# Seeds: fuzz/corpus/<target>/ (small hand-made files, read only), files our own writers make
# (LLVMFuzzerInitialize with ARVIEW_FUZZ_WRITE_SEED) and, when ../shared/data is there, small
# real files from it. What a run finds interesting accumulates in build/fuzz/corpus/<target>/.
# Exit status: 0 when no target crashed, 1 otherwise.
set -euo pipefail

cd "$(dirname "$0")/.."
root=$(pwd)
seconds=${1:-20}
shift || true
all_targets=(fuzz_camera fuzz_recording fuzz_trajectory fuzz_eval fuzz_map_file fuzz_colmap_model fuzz_colmap_database fuzz_scene fuzz_gltf fuzz_flags fuzz_image fuzz_room_light fuzz_speech_markup fuzz_wav fuzz_dialogue)
targets=("$@")
[[ ${#targets[@]} -eq 0 ]] && targets=("${all_targets[@]}")
data=${ARVIEW_DATA_DIR:-$root/../shared/data}
[[ -d $data ]] || data=/work/shared/data

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -- --no-print-directory | grep -E 'error|warning' || true
build=$root/build/fuzz

# Real small files from the shared data, copied into the run's own corpus (not the repo).
seed_from_data() {
  local target=$1 out=$2
  [[ -d $data ]] || return 0
  case $target in
    fuzz_camera) cp "$data/phone-fox/camera.yaml" "$out/phone-fox-camera.yaml" 2>/dev/null || true ;;
    fuzz_trajectory) head -n 40 "$data/phone-fox/groundtruth.txt" >"$out/phone-fox-groundtruth.txt" 2>/dev/null || true ;;
    fuzz_recording)
      if [[ -f $data/phone-fox/groundtruth.txt ]]; then
        { printf '0 frames/000000.png\n1 frames/000001.png\n2 frames/000002.png\n=====\n'
          head -n 3 "$data/phone-fox/groundtruth.txt"; } >"$out/phone-fox-groundtruth"
      fi ;;
    fuzz_gltf) cp "$data/characters/RiggedSimple.glb" "$out/" 2>/dev/null || true ;;
  esac
}

max_len_of() {
  case $1 in
    fuzz_gltf) echo 80000 ;;   # RiggedSimple.glb is 69 kB
    fuzz_map_file | fuzz_colmap_model | fuzz_dialogue) echo 16384 ;;
    fuzz_speech_markup) echo 4096 ;;
    *) echo 8192 ;;
  esac
}

# One process at a time: libFuzzer's default. (-jobs=1 would fork a child that writes
# fuzz-0.log into the current folder.)
failed=0
printf '%-20s %8s %12s %8s %8s %s\n' target seconds executions cov crashes artifacts
for target in "${targets[@]}"; do
  binary=$build/fuzz/$target
  [[ -x $binary ]] || { echo "$target: not built ($binary)" >&2; failed=1; continue; }
  corpus=$build/corpus/$target
  crashes=$build/crashes/$target
  mkdir -p "$corpus" "$crashes"
  seed_from_data "$target" "$corpus"
  seeds=()
  [[ -d fuzz/corpus/$target ]] && seeds+=("fuzz/corpus/$target")
  log=$build/logs/$target.log
  mkdir -p "$(dirname "$log")"
  status=0
  ARVIEW_FUZZ_WRITE_SEED=$corpus \
  ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "$binary" "$corpus" "${seeds[@]}" -max_total_time="$seconds" -max_len="$(max_len_of "$target")" \
      -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$crashes/" >"$log" 2>&1 || status=$?
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -n 1 | cut -d' ' -f2)
  found=$(find "$crashes" -type f \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' \) | wc -l)
  printf '%-20s %8s %12s %8s %8s %s\n' "$target" "$seconds" "${executions:-?}" "${cov:-?}" "$found" \
    "$( ((found > 0)) && echo "$crashes" || true)"
  if ((status != 0)); then
    failed=1
    grep -m1 -E 'ERROR: (libFuzzer|AddressSanitizer|UndefinedBehaviorSanitizer)|runtime error:' "$log" >&2 || true
    echo "  log: $log" >&2
  fi
done
exit $failed
