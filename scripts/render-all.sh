#!/usr/bin/env bash
# Quick start, first command: install what is missing, build in Release, render every scene into
# out/SCENE/frame_NNNNNN.png. Extra arguments go to `cps render all` (e.g. --seconds 2).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
cps_install_missing
cps_build
./build/demos/cps render all --out out "$@"
