#!/usr/bin/env bash
# A venue of rendered rooms joined by doors (`arview synth venue`, docs/render.md) mapped as one
# venue from one recording per room, each room also mapped alone, and a walk through the first
# door tracked on the venue's map (docs/mapping.md, "A venue of rendered rooms joined by doors"),
# the rooms alone last (the longest part).
#
#   bash scripts/venue-rooms.sh [/tmp/arview-venue-rooms]
#
# VENUE_FRAMES (600): the whole walk's frames; VENUE_STEP (2): every how many frames a room's
# recording takes (the walk turns up to 4.8 degrees a frame at 600 frames: at 2, 9.6 degrees from
# one frame to the next, and every frame registered; at 8 frames of 720, 24-32 degrees, a room's
# turn was lost, docs/mapping.md); VENUE_ROOMS (3). A re-run keeps the recordings and re-uses
# the maps' finished stages (arview map's stage records).
set -euo pipefail
cd "$(dirname "$0")/.."
arview="$(pwd)/${ARVIEW:-build/release/app/arview}"
out="${1:-/tmp/arview-venue-rooms}"
frames="${VENUE_FRAMES:-600}" step="${VENUE_STEP:-2}" rooms_count="${VENUE_ROOMS:-3}"
mkdir -p "$out"
cd "$out"

synth() { "$arview" synth venue --rooms "$rooms_count" --frames "$frames" --quiet "$@"; }
# The frames' rooms: rooms.txt of a sparse render of the whole walk (its ground truth is the
# venue's, every keyframe's timestamp in it).
[ -f plan/rooms.txt ] || synth --out plan --subset "0-$((frames - 1)):$step"
mapfile -t rooms < <(grep -v '^#' plan/rooms.txt | awk '{ print $2 }' | uniq)
frame_list() {  # the walk's frame indices of room $1 in plan/
  grep -v '^#' plan/rooms.txt | awk -v r="$1" '$2 == r { printf "%s%d", sep, $1 * 30 + 0.5; sep = "," }'
}
for room in "${rooms[@]}"; do
  [ -d "$room" ] || synth --out "$room" --subset "$(frame_list "$room")"
done
# Every frame from 2 s before the first door to 2 s after it (the walk crosses it ~6 s in at 600 frames).
# (awk reads the file itself: its early exit would otherwise end grep with SIGPIPE, which pipefail
# turns into the script's exit 141.)
first_door=$(awk -v r="${rooms[1]}" '!/^#/ && $2 == r { print int($1 * 30 + 0.5); exit }' plan/rooms.txt)
[ -d walk ] || synth --out walk --subset "$((first_door - 60))-$((first_door + 60))"

# --max-frames 0: every frame given (a venue of more than 300 frames is otherwise thinned evenly).
echo "== the venue, ${#rooms[@]} rooms as one map"
/usr/bin/time -f "venue map: %e s wall" "$arview" map "${rooms[@]}" --out venue --preset fast --matcher sequential --max-frames 0
"$arview" map info venue | sed -n '/^rooms/,/^[a-z]/p'
"$arview" eval venue/keyframes.txt plan/groundtruth.txt
for room in "${rooms[@]}"; do
  # The venue's keyframes of this room, against the same ground truth.
  grep -v '^#' "$room/frames.txt" | awk '{ print $1 }' > "$room.times"
  awk 'NR == FNR { t[sprintf("%.4f", $1)] = 1; next } /^#/ || t[sprintf("%.4f", $1)]' "$room.times" venue/keyframes.txt > "venue-$room.txt"
  echo "== $room in the venue's map"
  "$arview" eval "venue-$room.txt" plan/groundtruth.txt
done
echo "== the walk through the first door, tracked on the venue's map"
"$arview" track walk --map venue --out walk-track.txt --stats walk-stats.json
"$arview" eval walk-track.txt walk/groundtruth.txt
python3 - <<'PY'
import json
frames = json.load(open("walk-stats.json"))["frames"]
rooms = [f.get("room", "lost") for f in frames]
changes = [(frames[i]["index"], rooms[i - 1], rooms[i]) for i in range(1, len(rooms)) if rooms[i] != rooms[i - 1]]
print(f"walk: {len(frames)} frames, {rooms.count('lost')} lost; room changes: {changes}")
PY
for room in "${rooms[@]}"; do
  echo "== $room alone"
  /usr/bin/time -f "$room alone: %e s wall" "$arview" map "$room" --out "alone-$room" --preset fast --max-frames 0
  "$arview" eval "alone-$room/keyframes.txt" plan/groundtruth.txt
done
