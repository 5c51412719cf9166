#!/usr/bin/env bash
# The state hash at the end of every paper and stress scene (each at its own duration) for every
# combination of --push (every push method the binary offers), --solver and --assembly, one line
# each:
#   SCENE PUSH SOLVER ASSEMBLY HASH
# Usage: scripts/state-hashes.sh [CPS]               print the table (CPS: default build/demos/cps)
#        scripts/state-hashes.sh --check FILE [CPS] [K/N]
#                                 rerun the runs of FILE (with K/N: its runs K, K + N, ...)
#                                 with --expect-hash, where a line that repeats an earlier
#                                 line's run under a setting its push does not read is the
#                                 same run; exit 1 listing the lines whose state differs;
#                                 exit 77 (skipped) on a machine whose floating-point
#                                 features differ from those the table's "# machine:" line names
# A refactoring that must not change the physics keeps every hash (docs/state_hashes.txt holds
# the table of the last change that was meant to keep them). Hashes are of IEEE-754 bytes: a
# different compiler, flags or libm (glibc picks sin/cos variants by CPU) may change them.
set -euo pipefail
cd "$(dirname "$0")/.."
# What the hashes depend on besides the build: the architecture and the CPU features by which
# glibc picks its libm variants.
machine() {
  echo "$(uname -m) $(grep -o -w -E 'fma|avx2' /proc/cpuinfo 2> /dev/null | sort -u | tr '\n' ' ' | sed 's/ $//')"
}
if [ "${1:-}" = "--check" ]; then
  table=${2:?--check needs the table file}
  cps=${3:-build/demos/cps}
  part=${4:-1/1}
  k=${part%/*} n=${part#*/}
  [[ "$k" =~ ^[1-9][0-9]*$ && "$n" =~ ^[1-9][0-9]*$ && "$k" -le "$n" ]] ||
    { echo "state-hashes.sh: part '$part' is not K/N with 1 <= K <= N" >&2; exit 2; }
  made_on=$(sed -n 's/^# machine: //p' "$table")
  if [ -n "$made_on" ] && [ "$made_on" != "$(machine)" ]; then
    echo "state hashes skipped: the table was made on '$made_on', this machine is '$(machine)'"
    echo "(hashes of IEEE-754 bytes follow the libm variant glibc picks by CPU features)"
    exit 77
  fi
  # A line whose scene, push and hash an earlier line has, under a solver or assembly the push
  # does not read (`cps parameters --format json`: each push's "reads"), is that line's run
  # again: it is not run twice. That such settings change nothing is a test of its own
  # (tests/physics/test_push_methods.cpp).
  runs=$("$cps" parameters --format json | python3 -c '
import json, sys
reads = {c["name"]: c["reads"] for p in json.load(sys.stdin) if p["name"] == "push" for c in p["choices"]}
seen = set()
for text in open(sys.argv[1]):
    f = text.split()
    if len(f) != 5 or f[0].startswith("#"):
        continue
    scene, push, solver, assembly, hash = f
    r = reads.get(push, {})
    key = (scene, push, solver if r.get("solver", True) else "", assembly if r.get("assembly", True) else "", hash)
    if key not in seen:
        seen.add(key)
        print(text.strip())
' "$table")
  lines=$(grep -c -v -E '^(#|$)' "$table")
  echo "$lines lines, $(grep -c . <<< "$runs") runs (the others repeat one under a setting its push does not read)"
  failed=0
  checked=0
  line=0
  while read -r scene push solver assembly hash; do
    case "$scene" in ''|'#'*) continue ;; esac
    line=$((line + 1))
    [ $(((line - 1) % n)) -eq $((k - 1)) ] || continue
    checked=$((checked + 1))
    if ! "$cps" simulate "$scene" --push "$push" --solver "$solver" --assembly "$assembly" \
        --expect-hash "$hash" > /dev/null 2> /tmp/cps-state-hash.$$; then
      echo "DIFFERS: $scene $push $solver $assembly: $(tail -1 /tmp/cps-state-hash.$$)"
      failed=$((failed + 1))
    fi
  done <<< "$runs"
  rm -f /tmp/cps-state-hash.$$
  echo "$((checked - failed)) passed, $failed failed"
  [ "$failed" -eq 0 ]
  exit
fi
cps=${1:-build/demos/cps}
# The long runs (NAME_long: 10,000 steps of stack_20 and of the 20-row pyramid) are left out: at
# 20 combinations each they would take the table about 15 minutes, and they start as the scaled
# scenes stack_20 and pyramid_210, which the table leaves out too.
scenes=$("$cps" list | awk '/^Scaled/{exit} /^  /{print $1}' | grep -v '_long$')
echo "# scene push solver assembly state_hash   ($("$cps" simulate stack --seconds 0.02 --json | sed -n 's/.*"engine_version": "\(.*\)".*/\1/p'))"
echo "# machine: $(machine)"
# The push methods as the binary's --help lists them: "--push {baumgarte, split, ...}".
pushes=$("$cps" simulate --help | sed -n 's/^ *--push {\([^}]*\)}.*/\1/p' | tr -d ',')
[ -n "$pushes" ] || { echo "state-hashes.sh: no --push methods in '$cps simulate --help'" >&2; exit 1; }
for scene in $scenes; do
  for push in $pushes; do
    for solver in pgs jacobi; do
      for assembly in explicit matrix-free; do
        hash=$("$cps" simulate "$scene" --push "$push" --solver "$solver" --assembly "$assembly" \
          --json 2>/dev/null | sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p')
        echo "$scene $push $solver $assembly $hash"
      done
    done
  done
done
