#!/usr/bin/env bash
# make test's phases: run one quietly into build/logs/NAME.log and print one line (what ran,
# how many checks, the time); on failure, the log's last lines and a nonzero exit.
set -uo pipefail
name=$1; shift
logs=${VPDS_LOGS:-build/logs}
mkdir -p "$logs"
log="$logs/$name.log"
start=$(date +%s)
"$@" > "$log" 2>&1
status=$?
secs=$(( $(date +%s) - start ))
if [ $status -ne 0 ]; then
  echo "$name: FAILED after ${secs}s (status $status); the end of $log:"
  tail -n 60 "$log" | sed 's/^/    /'
  exit 1
fi
# what the phase counted: C tests print "ok: N checks", pytest "N passed", scripts a "summary:" line
programs=$(grep -cE '^ok: [0-9]+ checks' "$log" || true)
if [ "$programs" -gt 0 ]; then
  checks=$(grep -oE '^ok: [0-9]+' "$log" | awk '{s += $2} END {print s}')
  what="$programs programs, $checks checks passed"
elif grep -qE '^=* ?[0-9]+ passed' "$log"; then
  what=$(grep -E '^=* ?[0-9]+ passed' "$log" | tail -1 | sed 's/=//g; s/^ *//; s/ *$//')
else
  what=$(grep -E '^summary: ' "$log" | sed 's/^summary: //' | paste -sd ';' - | sed 's/;/; /g')
  [ -n "$what" ] || what="passed"
fi
printf '%-18s %s (%ss)\n' "$name:" "$what" "$secs"
