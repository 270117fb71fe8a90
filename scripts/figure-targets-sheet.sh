#!/usr/bin/env bash
# Makes docs/figure-targets.png, the built-in figure's morph-target contact sheet: the face from
# 0.6 m straight in front (640x480, f = 600 px, fixed lighting, gaze off), at rest, on each of the
# 15 visemes and each of Ekman's six expressions (arview render --morph / --expression), cropped
# to the head and labelled. Needs build/release/app/arview and ffmpeg (with drawtext).
#   bash scripts/figure-targets-sheet.sh [out.png]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-docs/figure-targets.png}
arview=build/release/app/arview
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat > "$work/scene.yaml" <<'YAML'
characters:
  - asset: builtin:figure
    gaze: {enabled: false}
    keys: [{azimuth: 0, pose: rest}]
YAML
cat > "$work/camera.yaml" <<'YAML'
%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 600., 0., 320., 0., 600., 240., 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 0., 0., 0., 0., 0. ]
YAML
# 0.6 m in front of the point between the eyes (0, 1.635, 0.094), looking back along -Z.
pose="0 1.635 0.694 1 0 0 0"
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
n=0
tile() {  # label, then arview render's morph flags
  local label=$1
  shift
  local frame="$work/frame.png" tile
  tile=$(printf '%s/tile_%02d.png' "$work" "$n")
  "$arview" render --scene "$work/scene.yaml" --camera "$work/camera.yaml" --pose "$pose" --lighting fixed --no-shadow \
    --out "$frame" "$@" >/dev/null
  ffmpeg -loglevel error -y -i "$frame" -vf "crop=180:250:230:112,pad=180:272:0:0:white,drawtext=fontfile=$font:text='$label':x=(w-text_w)/2:y=266-max_glyph_a:fontsize=15:fontcolor=black" "$tile"
  n=$((n + 1))
}
tile "rest"
for v in sil PP FF TH DD kk CH SS nn RR aa E ih oh ou; do tile "viseme_$v" --morph "viseme_$v=1"; done
for e in happy sad angry surprised afraid disgusted; do tile "$e" --expression "$e"; done
ffmpeg -loglevel error -y -framerate 1 -i "$work/tile_%02d.png" -vf "tile=8x3:padding=2:color=white" -frames:v 1 "$out"
echo "wrote $out ($n faces)"
