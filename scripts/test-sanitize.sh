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
# intercept_tls_get_addr=0: GCC 12's sanitizer runtime takes a dynamic TLS block that happens to
# start 16 bytes past a page boundary for a glibc 2.19 header, and records the two words before it
# (ASan's chunk header) as that block's range; LeakSanitizer's tracer reads that range at exit and
# crashes ("Tracer caught signal 11", google/sanitizers#1322). Every process that renders
# allocates one dynamic TLS block, at an address that moves with the heap's history (paths,
# pids): this fits the rare exit-134 aborts of rendering cps children in CI. Dynamic TLS is then
# not scanned for roots; static TLS, stacks and globals still are. See docs/testing.md.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0
# Leaks inside a Debian library that cps cannot free, each explained: scripts/lsan-suppressions.txt.
export LSAN_OPTIONS=suppressions=$PWD/scripts/lsan-suppressions.txt
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Left to the Release build of the test command, which runs them too: the bad-input sweep (label
# sweep, ~1400 command lines; about 5 minutes here, and it found the same results in both
# builds) and the two report sweeps (about 5 and 4 minutes here, 1 to 2 minutes of report runs
# each in the Release build), and cps report push --quick (35 runs of the five push methods:
# 98 s here, 6 s in Release; the methods' own tests run here). Also left to Release, measured in a
# fresh clone (ASan / Release): the report's output rule test (307 s / 15 s: its report runs
# every push method), the allocation count of every paper scene (407 s / 17 s: a count, which
# the sanitizer's allocator does not change) and the two 600 s stack runs (91 + 48 s / 3 + 2 s),
# so that .ci/run stays near 30 minutes on 2 cores. And the report --merge output tests (full
# disk, failing gnuplots, killed merges: 13 merges, each running the mass ratio study, 3 s in
# Release; the merge's refusals, which stop before it, run here).
# Box3D's two pyramids (5050 and 10,780 cubes, 200 steps: 45 s in Release) run in Release only.
# The random piles run 200 seeds in the Release tests; 50 here (under the sanitizers the 200 took
# 189 s of a 27.4-minute .ci/run).
export CPS_RANDOM_SEEDS=${CPS_RANDOM_SEEDS:-50}
ctest --test-dir build-asan --output-on-failure --parallel "$(nproc)" -LE sweep \
  -E "cps report's quick funnel sweep|cps report writes CSVs with units|cps report push --quick compares|cps report never overwrites a foreign report|after warm-up a step of every paper scene allocates nothing|for 600 s|report --merge on a full disk|report --merge checks gnuplot|temporaries of a killed report --merge|a killed report --merge|Box3D's pyramids stand 200 steps"
