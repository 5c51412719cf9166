#!/usr/bin/env bash
# Quick start, first command: install what is missing, build in Release, render every scene into
# out/SCENE/frame_NNNNNN.png, and the intersecting stack's two push variants side by side into
# out/intersecting_stack-compare-push/. Extra arguments go to both `cps render` calls
# (e.g. --seconds 2 --fps 10).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
cps_install_missing
cps_build
./build/demos/cps render all --out out "$@"
./build/demos/cps render intersecting_stack --compare push --out out "$@"
