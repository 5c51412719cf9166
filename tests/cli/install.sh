#!/usr/bin/env bash
# cmake --install into a new prefix: cps in PREFIX/bin runs from another folder and from PATH
# (it embeds its shaders, schema and example scenes), and PREFIX/share/cps holds the schema, the
# example scene files and the image baselines, which a render at their settings matches.
#
# Usage: install.sh CMAKE BUILD_DIR
set -euo pipefail
cmake=$1
build=$(cd "$2" && pwd)
scripts=$(cd "$(dirname "$0")/../../scripts" && pwd)
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
  # --prefix at the interpreter's user base (~/.local) installs into its user site, where a bare
  # `import cps` finds it.
  userbase="$dir/userbase"
  PYTHONUSERBASE=$userbase "$cmake" --install "$build" --prefix "$userbase" > "$dir/install-user.log" ||
    fail "$(cat "$dir/install-user.log")"
  usersite=$(PYTHONUSERBASE=$userbase "$PYTHON" -c 'import site; print(site.getusersitepackages())')
  found=$(PYTHONUSERBASE=$userbase "$PYTHON" -c 'import cps; print(cps.__file__)') ||
    fail "after cmake --install --prefix USERBASE, import cps fails"
  [[ $found == "$usersite"/cps.* ]] || fail "import cps found $found, not the module in $usersite"
  # The quick start's build (cps_link_python of scripts/deps.sh) makes a bare `import cps` find the
  # build folder's module; a second call keeps the same file.
  linkbase="$dir/linkbase"
  (source "$scripts/deps.sh" && PYTHONUSERBASE=$linkbase cps_link_python "$build") > "$dir/link.log" ||
    fail "cps_link_python failed: $(cat "$dir/link.log")"
  found=$(PYTHONUSERBASE=$linkbase "$PYTHON" -c 'import cps; print(cps.__file__)') ||
    fail "after cps_link_python, import cps fails"
  [[ $found == "$(cd "$build/python" && pwd)"/cps.* ]] || fail "after cps_link_python, import cps found $found"
  python_note="; the Python module in lib/python3/dist-packages and in a user site; the build's through cps-build.pth"
fi
echo "install: cps runs from $dir/prefix/bin; schema, ${#scenes[@]} example scenes and the baselines in share/cps$python_note"
