#!/usr/bin/env bash
# A rendered venue mapped across Slurm jobs, and its keyframes against the exact ground truth
# (issue 55; docs/mapping.md, "A rendered venue through Slurm"). `arview synth room` renders one
# walk round the synthetic room; its first half becomes the recording `east`, its second half
# `west` (--subset: every frame exactly as in the whole walk, timestamps included, so the two
# ground truths join without clashing). The two are mapped as one venue through a one-node Slurm
# cluster on this machine (scripts/slurm-local.sh, its own folder and ports), extraction and
# matching as jobs (VENUE_LEAF: the map in leaves too); then each half alone, here, for
# comparison. Prints the venue's rooms and, for the venue and each half, `arview eval` of its
# keyframes.
#
#   bash scripts/venue-synth.sh [work-folder]       # default /tmp/arview-venue-synth
#
# Environment: ARVIEW (the binary, default build/release/app/arview), VENUE_FRAMES (the walk's
# frames, default 300), VENUE_STEP (every n-th frame rendered, default 5), VENUE_LEAF (--leaf-size,
# default 0: one mapper, here; the 60 frames in leaves of 24 (overlap 10) or 40 (overlap 15) shared
# no registered image and the merge failed, saying so: docs/mapping.md), VENUE_OVERLAP
# (--leaf-overlap, default 15), VENUE_CHUNK (--slurm-chunk, default 15), VENUE_THREADS (--threads,
# default 2), VENUE_PRESET (--preset, default fast: the Slurm jobs match with COLMAP's matcher,
# and with 8,192 features the first of the four jobs of 1,770 pairs had not ended after 8 minutes).
# With the defaults on the 2-core machine at load 15-21: about 2 minutes of rendering, 15 of the
# venue's mapping (matching on Slurm 12 of them) and 6.5 for each half alone. Needs munge,
# slurmctld, slurmd, slurm-client (scripts/install-deps.sh) and root.
set -euo pipefail
cd "$(dirname "$0")/.."
arview="$(realpath "${ARVIEW:-build/release/app/arview}")"
work="${1:-/tmp/arview-venue-synth}"
frames="${VENUE_FRAMES:-300}"
step="${VENUE_STEP:-5}"
leaf="${VENUE_LEAF:-0}"
overlap="${VENUE_OVERLAP:-15}"
chunk="${VENUE_CHUNK:-15}"
threads="${VENUE_THREADS:-2}"
preset="${VENUE_PRESET:-fast}"
[ -x "$arview" ] || { echo "venue-synth: $arview not built (cmake --build build/release --target arview)" >&2; exit 1; }
half=$((frames / 2))
mkdir -p "$work"

stamp() { date -u +%H:%M:%S; }

render() {  # name, subset
  if [ ! -f "$work/$1/groundtruth.txt" ]; then
    echo "$(stamp) rendering $1 (frames $2 of the $frames-frame walk)"
    "$arview" synth room --out "$work/$1" --frames "$frames" --subset "$2" --quiet --force
  fi
}
render east "0-$((half - 1)):$step"
render west "$half-$((frames - 1)):$step"
grep -hv '^#' "$work/east/groundtruth.txt" "$work/west/groundtruth.txt" > "$work/groundtruth.txt"

# The cluster: its own folder and ports, so that it neither meets nor stops another user's.
export ARVIEW_SLURM_DIR="$work/slurm" ARVIEW_SLURMCTLD_PORT="${ARVIEW_SLURMCTLD_PORT:-6917}"
export ARVIEW_SLURMD_PORT="${ARVIEW_SLURMD_PORT:-6918}"
bash scripts/slurm-local.sh start
trap 'bash scripts/slurm-local.sh stop' EXIT
SLURM_CONF="$(bash scripts/slurm-local.sh conf)"
export SLURM_CONF

timed() {  # label, command...
  local label="$1"
  shift
  local t0
  t0=$(date +%s.%N)
  "$@"
  echo "$(stamp) $label: $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s wall," \
    "load average $(cut -d' ' -f1-3 /proc/loadavg)"
}

# A re-run skips the stages whose inputs did not change (docs/mapping.md, the stage records).
timed "venue through Slurm" "$arview" map "$work/east" "$work/west" --out "$work/venue" --threads "$threads" \
  --preset "$preset" --engine slurm --slurm-chunk "$chunk" --leaf-size "$leaf" --leaf-overlap "$overlap"
"$arview" map info "$work/venue"
echo "== the venue's keyframes against the ground truth"
"$arview" eval "$work/venue/keyframes.txt" "$work/groundtruth.txt"

for room in east west; do
  timed "$room alone, here" "$arview" map "$work/$room" --out "$work/$room-alone" --threads "$threads" --preset "$preset"
  echo "== $room alone against the ground truth"
  "$arview" eval "$work/$room-alone/keyframes.txt" "$work/$room/groundtruth.txt"
  echo "== $room's keyframes of the venue against the ground truth"
  "$arview" eval "$work/venue/keyframes.txt" "$work/$room/groundtruth.txt" ||
    echo "(the venue's map holds too few of $room's frames to align them)"
done
