#!/usr/bin/env bash
# The in-process tests again in a sanitizer build (build-asan/): AddressSanitizer (with
# LeakSanitizer) and UndefinedBehaviorSanitizer including float-cast-overflow; any report aborts
# the test that made it. -O1 keeps the build and the physics tests quick enough for CI; without
# debug information (a fifth less compile time) a report names each frame's function, not its
# line: rebuild with -g1 in CMAKE_CXX_FLAGS_RELWITHDEBINFO to see lines. Installs what is missing
# first, like the quick-start scripts.
#
# What runs here: the binaries that never start the cps command (ctest label in-process: the
# engine, the scenes and scene files, the exact reference, the output rule, image differences,
# the renderer and the caption page), built alone. The tests' own files are not instrumented
# (docs/testing.md: the code they call is). Every test, these included, runs in the
# Release build of the test command (scripts/test.sh); the command-line tests, which start cps
# hundreds of times, run only there. Not in .ci/run (it would take CI over 25 minutes on 2 cores):
# run it by hand before a change to the engine, the renderer, the scenes or the analysis lands.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
cps_install_missing
cps_configure build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g0" -DCPS_SANITIZE=ON -DCPS_BUILD_TESTS=ON
cmake --build build-asan --parallel "$(nproc)" --target cps_tests cps_output_tests \
  cps_compare_tests cps_renderer_tests cps_backend_tests cps_view_tests cps_compose_tests
# intercept_tls_get_addr=0: GCC 12's sanitizer runtime takes a dynamic TLS block that happens to
# start 16 bytes past a page boundary for a glibc 2.19 header, and records the two words before it
# (ASan's chunk header) as that block's range; LeakSanitizer's tracer reads that range at exit and
# crashes ("Tracer caught signal 11", google/sanitizers#1322). Every process that renders
# allocates one dynamic TLS block, at an address that moves with the heap's history (paths,
# pids). Dynamic TLS is then not scanned for roots; static TLS, stacks and globals still are.
# See docs/testing.md.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0
# Leaks inside a Debian library that cps cannot free, each explained: scripts/lsan-suppressions.txt.
export LSAN_OPTIONS=suppressions=$PWD/scripts/lsan-suppressions.txt
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Left to the Release build, which runs them too (seconds under ASan / in Release, on 2 cores):
# matrix-free lambda against the explicit path (89 / 5), the report headlines' trajectory times
# (66 / 4), the energy bound of every push method in the stiff scenes (28 / 2), the allocation
# count of every paper scene (a count, which the sanitizer's allocator does not change), the
# 600 s stack runs, Box3D's two pyramids, its wall of base 40 and every scene's default view (79 / 6),
# the random piles under the push methods beyond the paper's (55 / 10), xpbd's stack column
# (30 / 2) and the unread settings' runs (27 / 1); the random piles' NaN test stays here.
# The random piles run 200 seeds in the Release tests; 50 here.
export CPS_RANDOM_SEEDS=${CPS_RANDOM_SEEDS:-50}
ctest --test-dir build-asan --output-on-failure --parallel "$(nproc)" -L in-process \
  -E "matrix-free lambda equals the explicit path|report headline is its trajectory error|keep the energy bound in the stiff scenes|allocates nothing|for 600 s|Box3D's pyramids stand|Box3D's wall of base 40|every scene's default view shows its bodies|random piles keep the energy bound with the push methods beyond|xpbd keeps the paper's stack on its column|bit for bit the same under every value of a setting"
