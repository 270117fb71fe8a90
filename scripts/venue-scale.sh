#!/usr/bin/env bash
# The time of each stage of a map made through Slurm, with one and with two Slurm "nodes" of one
# CPU each (docs/mapping.md, "Scale, measured and modelled"): templeRing's 47 frames, extraction
# and matching as jobs of about 12 frames (--slurm-chunk 12), the map in two leaves
# (--leaf-size 24), every job on one CPU (--threads 1 --slurm-cpus 1), the fast preset. A node
# here is one CPU of this machine: the local cluster (scripts/slurm-local.sh, its own folder and
# ports 6937/6938) is started with ARVIEW_SLURM_CPUS=1, then 2, so Slurm runs one job at a time,
# then two. Each configuration maps from scratch (a fresh --out) SCALE_RUNS times (default 1).
#
#   ARVIEW_DATA_DIR=/work/shared/data bash scripts/venue-scale.sh [/tmp/arview-venue-scale]
#
# Writes <out>/times.txt: per run, each stage's wall time (first job's start to last job's end,
# from squeue, whole seconds), the sum of its jobs' times, the merge job's bundle adjustment
# (COLMAP's own figure in leaves/final.log), and arview's whole wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-/tmp/arview-venue-scale}"
arview="$(pwd)/${ARVIEW:-build/release/app/arview}"
data="${ARVIEW_DATA_DIR:-../shared/data}"
runs="${SCALE_RUNS:-1}"
mkdir -p "$out"
[ -d "$out/temple" ] || "$arview" import middlebury "$data/templeRing" --out "$out/temple"

export ARVIEW_SLURMCTLD_PORT=6937 ARVIEW_SLURMD_PORT=6938
cluster_stop() { bash scripts/slurm-local.sh stop >/dev/null 2>&1 || true; }
trap cluster_stop EXIT

# <jobs file> <job name>: "<wall> <sum>" in seconds over the jobs of that name (squeue's %S %e).
stage_times() {
  awk -v name="$2" '$2 == name {
      cmd = "date -d " $4 " +%s"; cmd | getline s; close(cmd)
      cmd = "date -d " $5 " +%s"; cmd | getline e; close(cmd)
      if (first == "" || s < first) first = s
      if (last == "" || e > last) last = e
      sum += e - s; n++ }
    END { if (n) printf "%d %d", last - first, sum; else printf "- -" }' "$1"
}

printf '%-6s %-4s %-14s %-14s %-14s %-14s %-9s %-7s\n' nodes run extract match leaves merge+ba ba wall > "$out/times.txt"
for run in $(seq "$runs"); do
  for cpus in 1 2; do
    # A fresh cluster per run: squeue then lists this run's jobs only.
    export ARVIEW_SLURM_DIR="$out/slurm-$cpus" ARVIEW_SLURM_CPUS=$cpus
    cluster_stop
    rm -rf "$ARVIEW_SLURM_DIR"
    bash scripts/slurm-local.sh start
    export SLURM_CONF="$ARVIEW_SLURM_DIR/slurm.conf"
    map="$out/map-$cpus-$run"
    rm -rf "$map"
    start=$(date +%s.%N)
    "$arview" map "$out/temple" --out "$map" --engine slurm --slurm-chunk 12 --leaf-size 24 \
      --threads 1 --slurm-cpus 1 --preset fast > "$out/map-$cpus-$run.log" 2>&1 ||
      { echo "venue-scale: arview map failed, see $out/map-$cpus-$run.log" >&2; exit 1; }
    wall=$(echo "$(date +%s.%N) - $start" | bc)
    jobs="$out/jobs-$cpus-$run.txt"
    squeue -h -r --states=all -o '%i %j %T %S %e' > "$jobs"
    ba=$(awk '/Bundle adjustment report/ { r = 1 } r && /Time :/ { t = $3; r = 0 } END { print t }' "$map/leaves/final.log")
    printf '%-6s %-4s %-14s %-14s %-14s %-14s %-9s %-7.1f\n' "$cpus" "$run" \
      "$(stage_times "$jobs" arview-map-extract)" "$(stage_times "$jobs" arview-map-match)" \
      "$(stage_times "$jobs" arview-map-leaves)" "$(stage_times "$jobs" arview-map-leaves-final)" \
      "$ba" "$wall" >> "$out/times.txt"
    echo "  load after run: $(cut -d' ' -f1-3 /proc/loadavg)" >> "$out/times.txt"
    cluster_stop
  done
done
echo "(each stage: wall from its first job's start to its last job's end, then the sum of its jobs' times; seconds)" >> "$out/times.txt"
cat "$out/times.txt"
