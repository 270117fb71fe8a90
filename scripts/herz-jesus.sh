#!/bin/bash
# Herz-Jesus-P25 (../shared/data/herz-jesus-p25: 25 photos of a church facade, 768x512, cameras
# from a laser-scan registration): the odd photos localized by `arview track` on default maps of
# the even ones, beside COLMAP's own registration of them into the same maps
# (scripts/colmap-register.sh). docs/tracker.md, "Herz-Jesus-P25: still photos of a large
# scene", has the figures this prints and why the maps are made several times (COLMAP is
# stochastic: the figure is the map's as much as the tracker's).
#
# usage: scripts/herz-jesus.sh <work> [maps=3] [arview=build/release/app/arview] [-- track flags...]
#
# In <work>: the import (hj), the maps (hmK, kept: a re-run reuses them), per map the tracked
# odd photos (hmK.txt, hmK.json) and COLMAP's registration (reg-hmK/). Prints one line a map
# (centre error median / RMSE in mm after Sim(3) on the map's keyframes, and the ratio) and the
# medians over the maps. ~10 min a map on 2 cores (COLMAP's extraction and matching), seconds
# for the tracking.
set -euo pipefail

work=${1:?usage: scripts/herz-jesus.sh <work> [maps] [arview] [-- track flags...]}
maps=${2:-3}
arview=${3:-build/release/app/arview}
shift $(($# < 3 ? $# : 3))
[ "${1:-}" = "--" ] && shift
track_flags=("$@")
here=$(cd "$(dirname "$0")" && pwd)
data=${ARVIEW_DATA_DIR:-$here/../../shared/data}/herz-jesus-p25
[ -d "$data" ] || { echo "$data: not found (set ARVIEW_DATA_DIR to the shared data folder)" >&2; exit 1; }
arview=$(realpath "$arview")
mkdir -p "$work"
cd "$work"

[ -f hj/frames.txt ] || "$arview" import strecha "$data" --out hj > /dev/null
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'; }
ate() {  # <estimate> <keyframes>: "median rmse" in mm
  "$arview" eval "$1" hj/groundtruth.txt --align sim3 --align-with "$2" --json |
    python3 -c 'import json, sys; a = json.load(sys.stdin)["ate"]; print("%.3f %.3f" % (a["median"] * 1000, a["rmse"] * 1000))'
}

: > summary.txt
for k in $(seq 1 "$maps"); do
  m=hm$k
  [ -f $m/map.arvmap ] || "$arview" map hj --out $m --frames 0-24:2 --threads 1 > $m.log 2>&1
  "$arview" track hj --map $m --frames 1-23:2 --out $m.txt --stats $m.json --threads 1 "${track_flags[@]}" > $m.track.log 2>&1
  [ -f reg-$m/registered.txt ] || "$here/colmap-register.sh" hj $m 1-23:2 reg-$m > /dev/null
  read -r a_med a_rmse < <(ate $m.txt $m/keyframes.txt)
  read -r c_med c_rmse < <(ate reg-$m/registered.txt $m/keyframes.txt)
  echo "$m $a_med $a_rmse $c_med $c_rmse $(grep -vc '^#' $m.txt) $(grep -vc '^#' reg-$m/registered.txt)" >> summary.txt
  printf '%s: arview %s / %s mm (%s of 12 photos), COLMAP %s / %s mm (%s), ratio %.2f\n' $m "$a_med" "$a_rmse" \
    "$(grep -vc '^#' $m.txt)" "$c_med" "$c_rmse" "$(grep -vc '^#' reg-$m/registered.txt)" "$(echo "$a_med / $c_med" | bc -l)"
done
a=$(awk '{ print $2 }' summary.txt | median)
c=$(awk '{ print $4 }' summary.txt | median)
printf 'median of the %d maps: arview %s mm, COLMAP %s mm, ratio %.2f\n' "$maps" "$a" "$c" "$(echo "$a / $c" | bc -l)"
