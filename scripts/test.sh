#!/usr/bin/env bash
# Quick start, second command: install what is missing, build, run every test through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/deps.sh
cps_install_missing
cps_build -DCPS_BUILD_TESTS=ON
ctest --test-dir build --output-on-failure --parallel "$(nproc)"
