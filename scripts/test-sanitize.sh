#!/usr/bin/env bash
# The tests again in a sanitizer build (build-asan/): AddressSanitizer (with LeakSanitizer) and
# UndefinedBehaviorSanitizer including float-cast-overflow; any report aborts the test that made
# it. -O1 keeps the build and the physics tests quick enough for CI. Installs what is missing
# first, like the quick-start scripts.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
cps_install_missing
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCPS_SANITIZE=ON -DCPS_BUILD_TESTS=ON
cmake --build build-asan --parallel "$(nproc)"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The bad-input sweep (label sweep, ~1300 command lines) runs in the Release build of the test
# command; here it would add about 5 minutes (it found the same results in both builds).
ctest --test-dir build-asan --output-on-failure --parallel "$(nproc)" -LE sweep
