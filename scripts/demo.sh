#!/usr/bin/env bash
# The README's main command: installs the Debian packages, builds arview (release preset) and
# runs the main job on the embedded default. No camera, no downloads.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target arview
bin=build/release/app/arview
"$bin" --help
out=${1:-out/demo}
mkdir -p "$out"
echo
echo "== Calibrating the camera of OpenCV's sample chessboard photos (Debian opencv-doc) =="
"$bin" calibrate --images "/usr/share/doc/opencv-doc/examples/data/left[0-9]*.jpg" --board 9x6 --square 0.025 \
  --out "$out/camera.yaml" --report "$out/calibration.png"
