#!/usr/bin/env bash
# cmake --install into a new prefix: cps in PREFIX/bin runs from another folder and from PATH
# (it embeds its shaders, schema and example scenes), and PREFIX/share/cps holds the schema, the
# example scene files and the image baselines, which a render at their settings matches.
#
# Usage: install.sh CMAKE BUILD_DIR
set -euo pipefail
cmake=$1
build=$2
dir=$(mktemp -d "${TMPDIR:-/tmp}/cps-install.XXXXXX")
trap 'rm -rf "$dir"' EXIT
fail() { echo "install: $1" >&2; exit 1; }

"$cmake" --install "$build" --prefix "$dir/prefix" > "$dir/install.log" || fail "$(cat "$dir/install.log")"
mkdir "$dir/elsewhere"
cd "$dir/elsewhere"
[ -x "$dir/prefix/bin/cps" ] || fail "no PREFIX/bin/cps"
# Whole outputs first: grep -q stopping early would end cps by SIGPIPE, a failure under pipefail.
listed=$(PATH="$dir/prefix/bin:$PATH" cps list) || fail "cps list from PATH failed"
grep -q '^  stack' <<< "$listed" || fail "cps list from PATH shows no stack"
ran=$(PATH="$dir/prefix/bin:$PATH" cps simulate dominoes --seconds 0.1 --json) ||
  fail "cps simulate of an example scene failed from PATH"
grep -q '"state_hash"' <<< "$ran" || fail "cps simulate --json of an example scene printed no state_hash"
share=$dir/prefix/share/cps
[ -f "$share/schemas/scene.schema.json" ] || fail "no PREFIX/share/cps/schemas/scene.schema.json"
scenes=("$share"/scenes/*.json)
[ -f "${scenes[0]}" ] || fail "no example scene files in PREFIX/share/cps/scenes"
[ -f "$share/baselines/stack/frame_000002.png" ] || fail "no baselines in PREFIX/share/cps/baselines"
# An installed example scene file runs by its path.
PATH="$dir/prefix/bin:$PATH" cps simulate "${scenes[0]}" --seconds 0.1 > /dev/null ||
  fail "an installed example scene file does not run"
# Where the Python module was built, it is installed and imports from PREFIX/lib/python3/dist-packages
# (PYTHON: the interpreter it was built for; PYTHON is unset where it was not built).
python_note=""
if [ -n "${PYTHON:-}" ]; then
  modules=("$dir"/prefix/lib/python3/dist-packages/cps*.so)
  [ -f "${modules[0]}" ] || fail "no Python module in PREFIX/lib/python3/dist-packages"
  hash=$(PYTHONPATH="$dir/prefix/lib/python3/dist-packages" "$PYTHON" -c \
         "import cps; r = cps.Run('stack'); r.advance_to(0.5); print(r.state_hash())") ||
    fail "the installed Python module does not import and step"
  expected=$(PATH="$dir/prefix/bin:$PATH" cps simulate stack --seconds 0.5 --json)
  grep -q "\"state_hash\": \"$hash\"" <<< "$expected" ||
    fail "the installed Python module's state hash $hash is not cps simulate's"
  python_note="; the Python module in lib/python3/dist-packages"
fi
echo "install: cps runs from $dir/prefix/bin; schema, ${#scenes[@]} example scenes and the baselines in share/cps$python_note"
