#!/usr/bin/env bash
# Installs every Debian 12 package arview needs to build, test and run. Idempotent: packages
# already present are left as they are. Run as root (or through sudo).
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config ccache git
  libopencv-dev libopencv-contrib-dev opencv-doc
  colmap
  libceres-dev libopengv-dev libflann-dev libeigen3-dev
  libv4l-dev
  libexif-dev
  libosmesa6-dev libegl-dev libgl-dev libgles-dev
  libassimp-dev assimp-testmodels
  libsqlite3-dev zlib1g-dev libjpeg62-turbo-dev libpng-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev
  ffmpeg
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev
  libyaml-cpp-dev nlohmann-json3-dev
  flite1-dev
  libasound2-dev libswresample-dev
  libpocketsphinx-dev libsphinxbase-dev pocketsphinx-en-us pocketsphinx-testdata
  libx11-dev libxext-dev libxrandr-dev
  xvfb
  xdotool
  x11-apps imagemagick
  mrcal libmrcal-dev python3-mrcal python3-opencv
  libmetis-dev
  slurmctld slurmd slurm-client munge
  python3
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages are already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps: must run as root to install: ${missing[*]}" >&2
    exit 1
  fi
fi

echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
if ! $SUDO apt-get install -y --no-install-recommends "${missing[@]}"; then
  echo "install-deps: apt-get install failed for: ${missing[*]}" >&2
  exit 1
fi

still_missing=()
for p in "${missing[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || still_missing+=("$p")
done
if [ ${#still_missing[@]} -ne 0 ]; then
  echo "install-deps: these packages are still missing: ${still_missing[*]}" >&2
  exit 1
fi
echo "install-deps: done"
