#!/usr/bin/env bash
# Runs the Python module's tests (tests/python/test_cps.py) with pytest. Exit 77 (skipped) where
# the interpreter lacks numpy or pytest. Usage: tests/python/run.sh PYTHON MODULE_DIR CPS
set -euo pipefail
python=$1
module_dir=$2
cps=$3
if ! "$python" -c "import numpy, pytest" 2> /dev/null; then
  echo "Python tests skipped: $python has no numpy or pytest (apt-get install python3-numpy python3-pytest)"
  exit 77
fi
cd "$(dirname "$0")"
PYTHONPATH="$module_dir${PYTHONPATH:+:$PYTHONPATH}" CPS_EXE="$cps" \
  "$python" -m pytest -q -p no:cacheprovider .
