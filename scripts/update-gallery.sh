#!/usr/bin/env bash
# Draws the gallery's figures again (docs/gallery/*.png.json): each sidecar records the command
# line that wrote its figure, which is run again from the repository root with the cps given
# (and --force, so that the figure, its sidecar and run.json are replaced); a command that wrote
# several figures (`figure paper`) runs once. Run it when a change of the pictures is meant
# (a camera rule, what an overlay draws) and say why in the commit. The animated GIF in the
# README is made by the render command the README gives beside it.
# Usage: scripts/update-gallery.sh [CPS] [FIGURE.png ...]
#   CPS: default build/demos/cps. FIGURE.png: only the figures named (file names in
#   docs/gallery); default: every one (the long runs take minutes each).
# Needs python3 (it reads the sidecars' JSON).
set -euo pipefail
cd "$(dirname "$0")/.."
cps=${1:-build/demos/cps}
shift || true
case $cps in /*) ;; *) cps=$PWD/$cps ;; esac
if [ ! -x "$cps" ]; then
  echo "update-gallery: $cps is not an executable cps; give the binary's path" >&2
  exit 2
fi
sidecars=()
if [ $# -eq 0 ]; then
  sidecars=(docs/gallery/*.png.json)
else
  for name in "$@"; do
    if [ ! -f "docs/gallery/$name.json" ]; then
      echo "update-gallery: docs/gallery/$name.json does not exist; give a figure's file name (e.g. fig6_stack.png)" >&2
      exit 2
    fi
    sidecars+=("docs/gallery/$name.json")
  done
fi
# One command line per line, NUL-free: each argument shell-quoted, the binary replaced, --force
# added where missing; duplicates (the figures of one command) once.
python3 - "$cps" "${sidecars[@]}" <<'EOF' > "${TMPDIR:-/tmp}/cps-gallery-commands.$$"
import json, shlex, sys
cps, seen = sys.argv[1], []
for path in sys.argv[2:]:
    argv = json.load(open(path))["command_line"][1:]
    if "--force" not in argv:
        argv.append("--force")
    line = " ".join(shlex.quote(a) for a in [cps] + argv)
    if line not in seen:
        seen.append(line)
print("\n".join(seen))
EOF
trap 'rm -f "${TMPDIR:-/tmp}/cps-gallery-commands.$$"' EXIT
while IFS= read -r line; do
  echo "update-gallery: ${line#"$cps "}" >&2
  eval "$line" < /dev/null
done < "${TMPDIR:-/tmp}/cps-gallery-commands.$$"
