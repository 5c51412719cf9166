#!/usr/bin/env bash
# The build without OSMesa (build-egl-only/, -DCPS_WITH_OSMESA=OFF, as on a machine whose Mesa has
# no libOSMesa, 25.1 and later): configures and builds cps, checks that it says the osmesa backend
# is left out and that --backend auto takes EGL, and renders the paper scenes' baselines through it
# (compared with cps diff at its default tolerance). Installs what is missing first, like the
# quick-start scripts.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
cps_install_missing
cmake -S . -B build-egl-only -DCMAKE_BUILD_TYPE=Release -DCPS_WITH_OSMESA=OFF \
  | grep 'osmesa backend is left out'
cmake --build build-egl-only --parallel "$(nproc)" --target cps
cps=$PWD/build-egl-only/demos/cps
version=$("$cps" --version)
printf '%s\n' "$version"
grep -q '^renderer: osmesa: .*built without' <<<"$version" ||
  { echo "test-egl-only: cps --version does not say the osmesa backend was left out" >&2; exit 1; }
grep -q '^--backend auto: egl' <<<"$version" ||
  { echo "test-egl-only: --backend auto does not take EGL" >&2; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/cps-egl-only.XXXXXX")
trap 'rm -rf "$work"' EXIT
for scene in stack intersecting_stack funnel pendulum_grid pendulum_wave; do
  (cd "$work" && "$cps" render "$scene" --seconds 2 --fps 1 --size 160x120 --out frames 2>/dev/null)
  "$cps" diff "assets/baselines/$scene" "$work/frames/$scene" --out "$work/diff-$scene"
done
echo "test-egl-only: passed"
