#!/usr/bin/env bash
# The README's commands as a reader types them: every `cps` and `cp` line of the shell blocks of
# its "Quick start" and "Gallery" sections runs from a scratch folder laid out as the repository
# (assets/, docs/gallery/, build/demos/cps) with build/demos on PATH and must exit 0; then every
# picture the README shows from docs/gallery/ must be a file those commands wrote under that
# name (but Blender's renders, blender_*.png), and a file of the repository. Exit 77 (skipped) without ffmpeg, which the GIF needs.
# Usage: tests/cli/readme.sh SOURCE_DIR CPS
set -euo pipefail
src=$1
cps=$2
if ! command -v ffmpeg > /dev/null; then
  echo "README test skipped: no ffmpeg for the gallery's GIF"
  exit 77
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/cps-readme.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/docs/gallery" "$work/build/demos"
ln -s "$src/assets" "$work/assets"
ln -s "$cps" "$work/build/demos/cps"
awk '/^## /{section=$0} /^```sh/{block=1; next} /^```/{block=0}
     block && (section == "## Quick start" || section == "## Gallery")' "$src/README.md" \
  > "$work/blocks"
grep -E '^(cps|cp) ' "$work/blocks" > "$work/commands" || true
count=$(wc -l < "$work/commands")
if [ "$count" -lt 5 ]; then
  echo "README test: found $count cps or cp lines in Quick start and Gallery; expected at least 5" >&2
  exit 1
fi
cd "$work"
while IFS= read -r line; do
  if ! (export PATH="$work/build/demos:$PATH"; bash -c "$line" > "$work/log" 2>&1 < /dev/null); then
    echo "README test: this command failed: $line" >&2
    cat "$work/log" >&2
    exit 1
  fi
done < "$work/commands"
shown=$(grep -o '!\[[^]]*\](docs/gallery/[^)]*)' "$src/README.md" | sed 's/.*(\(docs\/gallery\/[^)]*\))/\1/')
for picture in $shown; do
  # blender_*.png are Blender's renders of a `cps export`, made outside cps (docs/commands.md).
  if [ ! -f "$work/$picture" ] && [[ $picture != docs/gallery/blender_* ]]; then
    echo "README test: the README shows $picture, which none of its commands writes" >&2
    exit 1
  fi
  if [ ! -f "$src/$picture" ]; then
    echo "README test: the README shows $picture, which is not in the repository" >&2
    exit 1
  fi
done
echo "README: $count commands ran; $(echo "$shown" | wc -w) pictures shown, each written by them"
