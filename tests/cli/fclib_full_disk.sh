#!/usr/bin/env bash
# cps export --fclib on a full disk: libfclib ends its process when an HDF5 call fails, so cps
# writes through a child process and must still end with its own message naming the file and
# the system's reason, exit 1, and leave nothing in the folder. The disk is a 12 KiB tmpfs
# mounted in a private mount namespace (unshare -m). Exits 77 (ctest: skipped) where no mount
# namespace can be made or libfclib cannot be opened.
#
# Usage: fclib_full_disk.sh CPS
set -uo pipefail
cps=$(realpath "$1")
dir=$(mktemp -d "${TMPDIR:-/tmp}/cps-fclib-full.XXXXXX")
trap 'rm -rf "$dir"' EXIT
cd "$dir" || exit 1
export_line=(export intersecting_stack --seconds 0.1 --at 5 --fclib)
if ! "$cps" "${export_line[@]}" probe/s.hdf5 > /dev/null 2> probe.err; then
  grep -q "libfclib" probe.err && { echo "libfclib cannot be opened here: skipped"; exit 77; }
  cat probe.err >&2
  exit 1
fi
unshare -m true 2> /dev/null || { echo "no private mount namespace here (unshare -m): skipped"; exit 77; }
mkdir full
unshare -m bash -c 'mount -t tmpfs -o size=12k tmpfs full && cd full &&
  "$0" "${@}" s.hdf5 > ../out.txt 2> ../err.txt; echo $? > ../rc.txt; ls -A > ../left.txt' \
  "$cps" "${export_line[@]}" || { echo "tmpfs cannot be mounted here: skipped"; exit 77; }
rc=$(cat rc.txt)
err=$(cat err.txt)
echo "exit $rc: $err"
fail=0
[ "$rc" = 1 ] || { echo "FAIL: exit $rc, not 1" >&2; fail=1; }
grep -q -- "--fclib s.hdf5: nothing written" err.txt || { echo "FAIL: no message of cps's naming the file" >&2; fail=1; }
grep -q "No space left on device" err.txt || { echo "FAIL: the reason is not given" >&2; fail=1; }
[ ! -s left.txt ] || { echo "FAIL: left in the folder: $(tr '\n' ' ' < left.txt)" >&2; fail=1; }
exit $fail
