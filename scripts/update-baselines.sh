#!/usr/bin/env bash
# Renders the image baselines of the five paper scenes into assets/baselines/SCENE/ (frames at
# 0, 1 and 2 s, 160x120, the default view) and records the renderer that drew them
# (assets/baselines/renderer.txt: backend, GL renderer, Mesa and LLVM versions, as cps render
# prints them). tests/cli/test_cli_diff.cpp renders the same frames on each backend and compares
# them with `cps diff` (its default tolerance). Run it only when a change of the pictures is
# meant, and say why in the commit.
# Usage: scripts/update-baselines.sh [CPS]   (CPS: default build/demos/cps; --backend osmesa)
set -euo pipefail
cd "$(dirname "$0")/.."
cps=${1:-build/demos/cps}
case $cps in /*) ;; *) cps=$PWD/$cps ;; esac
work=$(mktemp -d "${TMPDIR:-/tmp}/cps-baselines.XXXXXX")
trap 'rm -rf "$work"' EXIT
renderer=
for scene in stack intersecting_stack funnel pendulum_grid pendulum_wave; do
  (cd "$work" && "$cps" render "$scene" --seconds 2 --fps 1 --size 160x120 --backend osmesa \
     --out frames) 2> "$work/$scene.err"
  renderer=$(grep -m1 '^render: ' "$work/$scene.err" | sed 's/^render: //')
  rm -rf "assets/baselines/$scene"
  mkdir -p "assets/baselines/$scene"
  cp "$work/frames/$scene"/frame_*.png "assets/baselines/$scene/"
done
printf '%s\n' "$renderer" > assets/baselines/renderer.txt
echo "baselines: assets/baselines ($renderer)"
