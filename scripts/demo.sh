#!/usr/bin/env bash
# The README's main command: installs the Debian packages, builds arview (release preset) and
# runs `arview demo` on the embedded default: no camera, no downloads. Extra arguments go to
# `arview demo` (e.g. --out demo.mp4 --work arview-demo).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target arview
exec build/release/app/arview demo "$@"
