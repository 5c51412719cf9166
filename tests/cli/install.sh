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
PATH="$dir/prefix/bin:$PATH" cps list | grep -q '^  stack' || fail "cps list from PATH shows no stack"
PATH="$dir/prefix/bin:$PATH" cps simulate dominoes --seconds 0.1 --json | grep -q '"state_hash"' ||
  fail "cps simulate of an example scene failed from PATH"
share=$dir/prefix/share/cps
[ -f "$share/schemas/scene.schema.json" ] || fail "no PREFIX/share/cps/schemas/scene.schema.json"
ls "$share"/scenes/*.json > /dev/null 2>&1 || fail "no example scene files in PREFIX/share/cps/scenes"
[ -f "$share/baselines/stack/frame_000002.png" ] || fail "no baselines in PREFIX/share/cps/baselines"
# An installed example scene file runs by its path.
PATH="$dir/prefix/bin:$PATH" cps simulate "$(ls "$share"/scenes/*.json | head -1)" --seconds 0.1 > /dev/null ||
  fail "an installed example scene file does not run"
echo "install: cps runs from $dir/prefix/bin; schema, $(ls "$share"/scenes/*.json | wc -l) example scenes and the baselines in share/cps"
