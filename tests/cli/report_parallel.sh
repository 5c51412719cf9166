#!/usr/bin/env bash
# A sweep of cps report on GNU parallel (Debian's `parallel`), as docs/commands.md shows it: the
# runs of `--list-runs` run by parallel with a job log, parallel stopped half way (TERM: no new
# job starts), the sweep completed with --resume-failed, which runs only the jobs the log does not
# show done, then merged into a complete report. Exits 77 (ctest: skipped) without parallel.
#
# Usage: report_parallel.sh CPS
set -euo pipefail
cps=$1
command -v parallel > /dev/null ||
  { echo "GNU parallel is not installed (apt-get install parallel): skipped"; exit 77; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/cps-report-parallel.XXXXXX")
trap 'rm -rf "$dir"' EXIT
cd "$dir"
fail() { echo "report_parallel: $1" >&2; exit 1; }

# A 0.2 s scene file of one box on a plane: the quick sweep's runs take milliseconds each.
cat > drop.json << 'EOF'
{"seconds": 0.2, "bodies": [{"shape": "plane", "normal": [0, 1, 0], "offset_m": 0},
 {"shape": "box", "half_extents_m": [0.5, 0.5, 0.5], "mass_kg": 1, "position_m": [0, 0.6, 0]}]}
EOF
"$cps" report drop.json --quick --list-runs --out sweep | grep -v '^#' > runs.txt
planned=$(wc -l < runs.txt)
[ "$planned" -gt 10 ] || fail "--list-runs listed $planned runs"

# One job at a time, so that the stop falls between jobs; TERM once half the log is written.
parallel --will-cite --joblog jobs.log -j 1 < runs.txt > /dev/null 2>&1 &
pid=$!
for _ in $(seq 600); do
  [ "$(($(wc -l 2> /dev/null < jobs.log || echo 1) - 1))" -ge $((planned / 2)) ] && break
  sleep 0.1
done
kill -TERM "$pid" 2> /dev/null || true
wait "$pid" || true  # parallel exits non-zero when stopped
done_first=$(($(wc -l < jobs.log) - 1))
[ "$done_first" -lt "$planned" ] || fail "parallel finished all $planned jobs before it was stopped"
[ "$done_first" -ge $((planned / 2)) ] || fail "the log shows $done_first jobs, less than half"
csvs=$(find sweep/runs -name '*.csv' | wc -l)
[ "$csvs" -lt "$planned" ] || fail "$csvs run CSVs after the stop, of $planned planned"
# Merged now: the missing runs are named and the report is INCOMPLETE (exit 1).
rc=0
"$cps" report --merge sweep/runs --out partial > /dev/null 2> partial.err || rc=$?
[ "$rc" -eq 1 ] || fail "merging the stopped sweep exited $rc, not 1"
grep -q "planned runs are missing" partial.err || fail "merging the stopped sweep named no missing run"

# Completed: only the jobs not done run again, and the merge is complete.
parallel --will-cite --joblog jobs.log --resume-failed -j 2 < runs.txt > /dev/null 2>&1 ||
  fail "parallel --resume-failed failed"
rows=$(($(wc -l < jobs.log) - 1))
[ "$rows" -eq "$planned" ] || fail "the job log has $rows jobs after --resume-failed, not $planned"
csvs=$(find sweep/runs -name '*.csv' | wc -l)
[ "$csvs" -eq "$planned" ] || fail "$csvs run CSVs, not $planned"
"$cps" report --merge sweep/runs --out sweep > /dev/null 2> merge.err || fail "$(cat merge.err)"
grep -q INCOMPLETE sweep/report.md && fail "the completed sweep's report is INCOMPLETE"
echo "report_parallel: $planned runs, $done_first before the stop, merged complete"
