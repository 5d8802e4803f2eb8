#!/usr/bin/env bash
# Runs each file of DIR once through a libFuzzer harness (ASan, UBSan; a per-input timeout of
# TIMEOUT seconds, 120 unless given, far above the regressions kept there) and says in one line
# how many ran and the slowest; a crash, leak, hang or broken invariant shows the harness's
# report and exits 1. libFuzzer writes no artifact for inputs given as files.
# usage: fuzz/replay_sanitized.sh HARNESS DIR [TIMEOUT]
set -u
bin=$1 dir=$2 timeout=${3:-120}
files=()
for f in "$dir"/*; do [ -f "$f" ] && files+=("$f"); done
if [ ${#files[@]} -eq 0 ]; then
  echo "FAIL: no input file in $dir"
  exit 1
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! ASAN_OPTIONS=allocator_may_return_null=1 "$bin" -rss_limit_mb=2048 -timeout="$timeout" \
    "${files[@]}" > "$log" 2>&1; then
  echo "FAIL: $bin on $dir"
  if grep -qE 'ERROR|invariant broken|runtime error' "$log"; then
    awk '/ERROR|invariant broken|runtime error/ { on = 1 } on' "$log" | head -n 40 | sed 's/^/    /'
  else
    tail -n 20 "$log" | sed 's/^/    /'
  fi
  exit 1
fi
[ "$(grep -c '^Executed ' "$log")" = "${#files[@]}" ] || { echo "FAIL: not every input of $dir ran"; cat "$log"; exit 1; }
ms=$(sed -n 's/^Executed .* in \([0-9]*\) ms$/\1/p' "$log" | sort -n | tail -1)
printf '%-24s%s inputs under the sanitizers, slowest %s ms\n' "" "${#files[@]}" "${ms:-?}"
