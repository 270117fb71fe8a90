#!/bin/bash
# COLMAP's own registration of a recording's frames into an arview map, the reference that
# docs/tracker.md compares `arview track` with (templeRing, phone-fox, Herz-Jesus-P25).
#
# usage: scripts/colmap-register.sh <recording> <map> <frames> <work> [threads]
#
# <frames>: the frames to register, as `arview track --frames` takes them but only the a-b:s
# form (e.g. 1-23:2). Into a copy of the map's database and model (the map folder is left as
# it is), in <work>: the frames' SIFT with the map's own extraction options (the map's
# stages/extract.inputs: camera model and parameters, features, orientations, first octave),
# COLMAP's matcher on every new frame x every keyframe (matches_importer, pairs), then
# image_registrator with the camera held (no focal length, principal point or distortion
# refinement). Writes <work>/registered.txt (the frames, TUM, camera-to-world, timestamps from
# the recording's frames.txt) and <work>/keyframes.txt (the map's frames as COLMAP left them),
# for `arview eval <work>/registered.txt <groundtruth> --align-with <map>/keyframes.txt`.
set -euo pipefail

if [ $# -lt 4 ]; then
  sed -n '4,6p' "$0" >&2
  exit 2
fi
recording=$(realpath "$1")
map=$(realpath "$2")
frames=$3
work=$4
threads=${5:-1}

for f in "$recording/frames.txt" "$map/database.db" "$map/stages/extract.inputs" "$map/image_list.txt"; do
  [ -e "$f" ] || { echo "$f: not found (a recording and an arview map folder are needed)" >&2; exit 1; }
done
[ -d "$map/sparse" ] || { echo "$map/sparse: not found (the map's COLMAP model)" >&2; exit 1; }
if ! [[ $frames =~ ^([0-9]+)-([0-9]+)(:([0-9]+))?$ ]]; then
  echo "$frames: frames must be a-b or a-b:step" >&2
  exit 1
fi
first=${BASH_REMATCH[1]} last=${BASH_REMATCH[2]} step=${BASH_REMATCH[4]:-1}

mkdir -p "$work"
work=$(realpath "$work")
rm -rf "$work/database.db" "$work/sparse" "$work/out" "$work/txt"
sqlite3 "$map/database.db" "VACUUM INTO '$work/database.db'"
model=$(dirname "$(find "$map/sparse" -name images.bin | head -1)")
mkdir -p "$work/sparse" && cp -r "$model" "$work/sparse/0"

# The frames' image paths (frames.txt: "timestamp path", index = line among the frames)
grep -v '^#' "$recording/frames.txt" | awk -v a="$first" -v b="$last" -v s="$step" \
  'NR - 1 >= a && NR - 1 <= b && (NR - 1 - a) % s == 0 { print $2 }' > "$work/new_images.txt"
[ -s "$work/new_images.txt" ] || { echo "$frames: no such frames in $recording/frames.txt" >&2; exit 1; }

# The map's extraction options (one token a line in extract.inputs, the image list after them)
option() { awk -v key="$1" 'prev == key { print; exit } { prev = $0 }' "$map/stages/extract.inputs"; }
params=$(option --ImageReader.camera_params)
colmap feature_extractor --database_path "$work/database.db" --image_path "$recording" \
  --image_list_path "$work/new_images.txt" --ImageReader.camera_model "$(option --ImageReader.camera_model)" \
  --ImageReader.existing_camera_id 1 --ImageReader.camera_params "$params" \
  --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads "$threads" \
  --SiftExtraction.max_num_features "$(option --SiftExtraction.max_num_features)" \
  --SiftExtraction.max_num_orientations "$(option --SiftExtraction.max_num_orientations)" \
  --SiftExtraction.first_octave "$(option --SiftExtraction.first_octave)" > "$work/colmap.log" 2>&1

while read -r new; do
  while read -r key; do echo "$new $key"; done < "$map/image_list.txt"
done < "$work/new_images.txt" > "$work/pairs.txt"
colmap matches_importer --database_path "$work/database.db" --match_list_path "$work/pairs.txt" \
  --match_type pairs --SiftMatching.use_gpu 0 --SiftMatching.num_threads "$threads" >> "$work/colmap.log" 2>&1

mkdir -p "$work/out" "$work/txt"
colmap image_registrator --database_path "$work/database.db" --input_path "$work/sparse/0" \
  --output_path "$work/out" --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_principal_point 0 \
  --Mapper.ba_refine_extra_params 0 >> "$work/colmap.log" 2>&1
colmap model_converter --input_path "$work/out" --output_path "$work/txt" --output_type TXT >> "$work/colmap.log" 2>&1

# images.txt: "id qw qx qy qz tx ty tz camera name" (world to camera) then a line of points.
# TUM: the centre -R^T t, the orientation conj(q) as qx qy qz qw.
to_tum() {
  awk -v list="$1" '
    FNR == NR { if ($1 !~ /^#/) stamp[$2] = $1; next }
    FILENAME == list { wanted[$1] = 1; next }
    /^#/ { next }
    ++n % 2 == 1 && ($10 in wanted) {
      w = $2; x = $3; y = $4; z = $5; tx = $6; ty = $7; tz = $8
      # R^T t with R from (w, x, y, z)
      r00 = 1 - 2*(y*y + z*z); r01 = 2*(x*y - w*z);     r02 = 2*(x*z + w*y)
      r10 = 2*(x*y + w*z);     r11 = 1 - 2*(x*x + z*z); r12 = 2*(y*z - w*x)
      r20 = 2*(x*z - w*y);     r21 = 2*(y*z + w*x);     r22 = 1 - 2*(x*x + y*y)
      cx = -(r00*tx + r10*ty + r20*tz); cy = -(r01*tx + r11*ty + r21*tz); cz = -(r02*tx + r12*ty + r22*tz)
      printf "%s %.12f %.12f %.12f %.12f %.12f %.12f %.12f\n", stamp[$10], cx, cy, cz, -x, -y, -z, w
    }' "$recording/frames.txt" "$1" "$work/txt/images.txt" | sort -g
}
{ echo "# COLMAP image_registrator: frames $frames of $recording into $map"; echo "# timestamp tx ty tz qx qy qz qw (camera-to-world)"; to_tum "$work/new_images.txt"; } > "$work/registered.txt"
{ echo "# COLMAP image_registrator: the keyframes of $map after it"; echo "# timestamp tx ty tz qx qy qz qw (camera-to-world)"; to_tum "$map/image_list.txt"; } > "$work/keyframes.txt"
echo "registered $(grep -vc '^#' "$work/registered.txt") of $(wc -l < "$work/new_images.txt") frames: $work/registered.txt"
