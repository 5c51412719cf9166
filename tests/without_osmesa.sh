#!/usr/bin/env bash
# Runs a test binary as on a machine without OSMesa (upstream Mesa dropped it in 25.1): libOSMesa
# is hidden in a private mount namespace (its file bound over by /dev/null, so dlopen fails), and
# `cps --version` must then say that --backend auto takes EGL.
# Usage: tests/without_osmesa.sh CPS TEST_BINARY [CATCH ARGS...]
# Exit 77 (ctest's skip) where no mount namespace can be made (not root, or no unshare).
set -u
cps=$1
shift
lib=$(ldconfig -p 2>/dev/null | awk '/libOSMesa\.so\.8 / {print $NF; exit}')
hide=
if [[ -n $lib ]]; then
  hide="mount --bind /dev/null '$(readlink -f "$lib")' &&"
fi
if ! unshare -m true 2> /dev/null; then
  echo "without_osmesa: cannot make a mount namespace here (unshare -m); skipped" >&2
  exit 77
fi
exec unshare -m bash -c "$hide
  version=\$('$cps' --version) || exit 1
  echo \"\$version\"
  grep -q '^--backend auto: egl' <<< \"\$version\" || { echo 'without_osmesa: auto does not take EGL' >&2; exit 1; }
  exec \"\$@\"" without_osmesa "$@"
