#!/usr/bin/env bash
# Speed check between two versions of cps: `cps bench --quick --json` of each, run in turns in
# one go (A B B A A B ...) so that the machine's load falls on both, then one Markdown table of
# the medians over the rounds and their ratios (NEW / OLD; above 1 is slower). A report, not a
# test: run it for every change to the engine or the renderer and give the ratios in the note
# (docs/benchmarks.md, "Speed check between changes").
#
# Usage: scripts/speed-check.sh [--rounds N] [--keep DIR] OLD [NEW]
#   OLD, NEW  a cps binary (a path to an executable file), or a git revision of this repository
#             (main, HEAD~3, a commit), which is checked out in a temporary worktree and built
#             (Release, target cps; ccache when installed). NEW defaults to build/demos/cps.
#   --rounds  bench runs of each version, in [1, 20]; default 2 (about 1 minute a run here)
#   --keep    a new folder (must not exist) that keeps each run's JSON; by default they are
#             removed with the temporary folder
# Exit status: 0 with the table, 1 when a build or a bench run fails, 2 for a usage error.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD

usage() {
  echo "speed-check: $1" >&2
  echo "usage: scripts/speed-check.sh [--rounds N] [--keep DIR] OLD [NEW]   (OLD, NEW: a cps binary or a git revision)" >&2
  exit 2
}

rounds=2
keep=
args=()
while [ $# -gt 0 ]; do
  case $1 in
    --rounds)
      [ $# -ge 2 ] || usage "--rounds needs a value"
      [[ $2 =~ ^[0-9]+$ ]] && [ "$2" -ge 1 ] && [ "$2" -le 20 ] ||
        usage "--rounds $2 is not allowed: it must be an integer in [1, 20]"
      rounds=$2; shift 2 ;;
    --keep)
      [ $# -ge 2 ] || usage "--keep needs a folder"
      [ ! -e "$2" ] || usage "--keep $2 already exists: give a new folder, nothing is written over"
      keep=$2; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) usage "unknown option $1" ;;
    *) args+=("$1"); shift ;;
  esac
done
[ ${#args[@]} -ge 1 ] && [ ${#args[@]} -le 2 ] || usage "give OLD and optionally NEW (got ${#args[@]} arguments)"
old_spec=${args[0]}
new_spec=${args[1]:-build/demos/cps}

# jq reads the bench JSON.
source scripts/deps.sh
cps_packages=(jq)
cps_install_missing

work=$(mktemp -d "${TMPDIR:-/tmp}/cps-speed-check.XXXXXX")
cleanup() {  # the temporary worktrees go with the folder; prune forgets them
  rm -rf "$work"
  git -C "$repo" worktree prune
}
trap cleanup EXIT

# resolve SPEC NAME: prints the path of a cps binary for SPEC (a binary, or a revision it builds).
resolve() {
  local spec=$1 name=$2
  if [ -f "$spec" ] && [ -x "$spec" ]; then
    case $spec in /*) echo "$spec" ;; *) echo "$repo/$spec" ;; esac
    return 0
  fi
  local commit
  if ! commit=$(git -C "$repo" rev-parse --verify --quiet "$spec^{commit}"); then
    echo "speed-check: $spec is neither an executable file nor a git revision of $repo" >&2
    exit 2
  fi
  local src=$work/src-$name bld=$work/build-$name launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  echo "speed-check: building $spec (${commit:0:12}) in $bld" >&2
  git -C "$repo" worktree add --detach --quiet "$src" "$commit"
  if ! { cmake -S "$src" -B "$bld" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" &&
         CCACHE_BASEDIR=$work cmake --build "$bld" --parallel "$(nproc)" --target cps; } > "$work/build-$name.log" 2>&1; then
    tail -20 "$work/build-$name.log" >&2
    echo "speed-check: building $spec failed (log above)" >&2
    exit 1
  fi
  echo "$bld/demos/cps"
}

old_cps=$(resolve "$old_spec" old)
new_cps=$(resolve "$new_spec" new)
echo "speed-check: OLD = $old_spec ($("$old_cps" --version | head -1)), NEW = $new_spec ($("$new_cps" --version | head -1))" >&2

# Rounds in the order A B, B A, A B, ...: each version runs first as often as second.
mkdir -p "$work/runs"
for ((r = 1; r <= rounds; r++)); do
  if ((r % 2)); then order=(old new); else order=(new old); fi
  for v in "${order[@]}"; do
    bin=$old_cps; [ "$v" = new ] && bin=$new_cps
    echo "speed-check: round $r of $rounds: $v (load $(cut -d' ' -f1-3 /proc/loadavg))" >&2
    (cd "$work/runs" && "$bin" bench --quick --json > "$v-$r.json") ||
      { echo "speed-check: $v's bench failed" >&2; exit 1; }
  done
done
[ -z "$keep" ] || { mkdir -p "$keep" && cp "$work/runs"/*.json "$keep/"; }

# One flat list of "key<TAB>value" per run: physics per scene, growth slopes, warm start, frames.
flatten='
  ((.physics // [])[] | [.scene + " | matrix-free us/step", .matrix_free_us_per_step],
                       [.scene + " | explicit us/step", .explicit_us_per_step]),
  ((.growth // [])[] | [.family + " | growth slope (against bodies)", .slope_against_bodies]),
  ((.rendering // [])[] | [.scene + " | frame end to end ms", .end_to_end_ms])'
for f in "$work/runs"/*.json; do
  jq -r "($flatten) | select(.[1] | type == \"number\") | @tsv" "$f" > "${f%.json}.tsv"
done

# Median of each key over a version's rounds, then the table.
median_of() {  # VERSION: prints "key<TAB>median"
  cat "$work/runs/$1"-*.tsv | sort -t$'\t' -k1,1 -k2,2g | awk -F'\t' '
    { v[$1] = v[$1] " " $2; n[$1]++; if (!($1 in seen)) { seen[$1] = 1; keys[++k] = $1 } }
    END { for (i = 1; i <= k; i++) { split(substr(v[keys[i]], 2), a, " "); c = n[keys[i]];
          m = (c % 2) ? a[(c + 1) / 2] : (a[c / 2] + a[c / 2 + 1]) / 2; print keys[i] "\t" m } }'
}
median_of old > "$work/old.tsv"
median_of new > "$work/new.tsv"

echo
echo "Speed check, $(date -u +%Y-%m-%dT%H:%MZ), $rounds round(s) of cps bench --quick each, medians:"
echo "OLD = $old_spec, NEW = $new_spec; NEW / OLD above 1 is slower (for the growth slope: steeper)."
echo
echo "| scene | measure | OLD | NEW | NEW / OLD |"
echo "|---|---|---|---|---|"
awk -F'\t' 'NR == FNR { old[$1] = $2; next }
  { split($1, p, " \\| "); o = ($1 in old) ? old[$1] : "";
    r = (o != "" && o + 0 != 0) ? sprintf("%.3f", $2 / o) : "-";
    printf "| %s | %s | %s | %.4g | %s |\n", p[1], p[2], (o == "" ? "-" : sprintf("%.4g", o)), $2, r }' \
  "$work/old.tsv" "$work/new.tsv"
