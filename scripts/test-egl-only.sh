#!/usr/bin/env bash
# The build without OSMesa (build-egl-only/, -DCPS_WITH_OSMESA=OFF, as on a machine whose Mesa has
# no libOSMesa, 25.1 and later). Only the renderer differs in such a build (the osmesa backend
# compiled without GL/osmesa.h), so only the renderer and its in-process tests are built here:
# configure says the backend is left out, the osmesa backend says so when asked for, --backend
# auto takes EGL, and the renderer's tests pass through EGL. The whole command through EGL (the
# paper scenes against their baselines, with libOSMesa hidden) runs in the test command's build.
# Installs what is missing first, like the quick-start scripts.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
cps_install_missing
cps_configure build-egl-only -DCMAKE_BUILD_TYPE=Release -DCPS_WITH_OSMESA=OFF -DCPS_BUILD_TESTS=ON \
  | grep 'osmesa backend is left out'
cmake --build build-egl-only --parallel "$(nproc)" --target cps_backend_tests cps_renderer_tests
tests=build-egl-only/tests
# Asked for, the osmesa backend says it was left out of the build (and that case is skipped).
out=$("$tests/cps_backend_tests" "OSMesa and EGL render the box and sphere scene into the same image")
grep -q "built without OSMesa's header" <<<"$out" ||
  { printf '%s\n' "$out"; echo "test-egl-only: the osmesa backend does not say it was left out" >&2; exit 1; }
# Every backend case (auto takes EGL: 'the auto backend takes OSMesa where it renders, else EGL')
# and every renderer case, through EGL.
"$tests/cps_backend_tests"
"$tests/cps_renderer_tests"
echo "test-egl-only: passed"
