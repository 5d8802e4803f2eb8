#!/usr/bin/env bash
# Runs test programs JOBS at a time (the machine's cores), each into its own log, then prints
# the logs in the programs' order (so "ok: N checks" lines stay countable) and fails if any
# program failed, naming it.
# usage: tools/run_tests.sh JOBS LOGDIR [--wrap "valgrind ..."] PROGRAM...
set -uo pipefail
jobs=$1 logs=$2
shift 2
wrap=""
if [ "${1:-}" = --wrap ]; then wrap=$2; shift 2; fi
mkdir -p "$logs"
export wrap logs
printf '%s\n' "$@" | xargs -P "$jobs" -I{} bash -c \
  'log="$logs/$(basename "{}").log"; $wrap {} > "$log" 2>&1; echo $? > "$log.status"'
failed=()
for t in "$@"; do
  log="$logs/$(basename "$t").log"
  echo "== ${wrap:+$wrap }$t"
  cat "$log"
  [ "$(cat "$log.status" 2>/dev/null)" = 0 ] || failed+=("$t (status $(cat "$log.status" 2>/dev/null))")
done
if [ ${#failed[@]} -gt 0 ]; then
  printf 'FAILED: %s\n' "${failed[@]}"
  exit 1
fi
