#!/usr/bin/env bash
# arview's calibration and mrcal's side by side on the same chessboard photos (docs/calibration.md,
# "Compared with mrcal"): the intrinsics, and the projection uncertainty at a working distance
# (worst-direction 1-sigma, pixels) at the image's centre, its median over a 32-column grid and
# its worst. Both fit OpenCV's 5-parameter lens model (mrcal's LENSMODEL_OPENCV5) to the same
# corners: found once with OpenCV's detector and refinement, as arview finds them (mrcal's own
# detector, mrgingham, reads square boards only), and given to mrcal as its corners cache.
#
#   scripts/compare-mrcal.sh [--images "<glob>"] [--board 9x6] [--square 0.025] [--distance 1] [--arview <binary>]
#
# Needs mrcal, python3-mrcal and python3-opencv (scripts/install-deps.sh).
set -euo pipefail

images="/usr/share/doc/opencv-doc/examples/data/left[0-9]*.jpg"
board=9x6
square=0.025
distance=1
arview="${ARVIEW_BIN:-build/release/app/arview}"
while [ $# -gt 0 ]; do
  case "$1" in
    --images) images=$2; shift 2 ;;
    --board) board=$2; shift 2 ;;
    --square) square=$2; shift 2 ;;
    --distance) distance=$2; shift 2 ;;
    --arview) arview=$2; shift 2 ;;
    *) echo "compare-mrcal: unknown argument $1" >&2; exit 2 ;;
  esac
done
columns=${board%x*}
rows=${board#*x}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The corners, as arview finds them: OpenCV's classic detector, refined with an 11x11 window.
/usr/bin/python3 - "$images" "$columns" "$rows" >"$work/corners.vnl" <<'PY'
import glob, sys
import cv2
pattern, columns, rows = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
print("# filename x y")
for name in sorted(glob.glob(pattern)):
    grey = cv2.imread(name, cv2.IMREAD_GRAYSCALE)
    found, corners = cv2.findChessboardCorners(grey, (columns, rows), flags=cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
    if not found:
        print(f"{name} - -")
        continue
    corners = cv2.cornerSubPix(grey, corners, (11, 11), (-1, -1), (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.0001))
    for x, y in corners.reshape(-1, 2):
        print(f"{name} {x:.4f} {y:.4f}")
PY

mrcal-calibrate-cameras --corners-cache "$work/corners.vnl" --lensmodel LENSMODEL_OPENCV5 --focal 500 \
  --object-spacing "$square" --object-width-n "$columns" --object-height-n "$rows" --outdir "$work" "$images" \
  >"$work/mrcal.log" 2>&1 || { cat "$work/mrcal.log" >&2; exit 1; }
"$arview" calibrate --images "$images" --board "$board" --square "$square" --distance "$distance" \
  --out "$work/arview.yaml" >"$work/arview.log" 2>&1 || { cat "$work/arview.log" >&2; exit 1; }

/usr/bin/python3 - "$work" "$distance" <<'PY'
import re, sys
import numpy as np
import cv2
import mrcal
work, distance = sys.argv[1], float(sys.argv[2])
model = mrcal.cameramodel(f"{work}/camera-0.cameramodel")
width, height = model.imagersize()
fx, fy, cx, cy, *dist = model.intrinsics()[1]
# The grid arview evaluates: 32 columns, rows in proportion, at the cells' centres.
columns = 32
rows = max(3, round(columns * height / width))
u = (np.arange(columns) + 0.5) * width / columns - 0.5
v = (np.arange(rows) + 0.5) * height / rows - 0.5
q = np.array([[x, y] for y in v for x in u] + [[(width - 1) / 2, (height - 1) / 2]], dtype=float)
p = mrcal.unproject(q, *model.intrinsics())
p = p / p[:, 2:3] * distance  # depth `distance` along the optical axis, as arview places them
sigma = mrcal.projection_uncertainty(p, model=model, what="worstdirection-stdev")
grid, centre = sigma[:-1], sigma[-1]
arview = cv2.FileStorage(f"{work}/arview.yaml", cv2.FILE_STORAGE_READ)
K = arview.getNode("camera_matrix").mat()
D = arview.getNode("distortion_coefficients").mat().ravel()
log = open(f"{work}/arview.log").read()
m = re.search(r"projection uncertainty at \S+ m: ([0-9.]+) px at the centre, median ([0-9.]+), worst ([0-9.]+)", log)
rms = re.search(r"RMS reprojection error\s+([0-9.]+)", log).group(1)
mrcal_log = open(f"{work}/mrcal.log").read()
mrcal_rms = re.search(r"RMS reprojection error: ([0-9.]+)", mrcal_log).group(1)
print(f"{'':24} {'arview':>12} {'mrcal':>12}")
for name, a, b in [("fx", K[0, 0], fx), ("fy", K[1, 1], fy), ("cx", K[0, 2], cx), ("cy", K[1, 2], cy),
                   ("k1", D[0], dist[0]), ("k2", D[1], dist[1]), ("p1", D[2], dist[2]), ("p2", D[3], dist[3]),
                   ("k3", D[4], dist[4])]:
    print(f"{name:24} {a:12.4f} {b:12.4f}")
print(f"{'RMS px':24} {rms:>12} {mrcal_rms:>12}")
print(f"{'uncertainty centre px':24} {float(m.group(1)):12.3f} {centre:12.3f}")
print(f"{'uncertainty median px':24} {float(m.group(2)):12.3f} {np.median(grid):12.3f}")
print(f"{'uncertainty worst px':24} {float(m.group(3)):12.3f} {grid.max():12.3f}")
PY
