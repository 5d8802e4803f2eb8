#!/usr/bin/env bash
# Runs each input of DIR once through a libFuzzer harness (ASan, UBSan, no per-input timeout) and
# says in one line how many ran and the slowest; a crash, leak or broken invariant shows the
# harness's report and exits 1 (libFuzzer's artifact goes beside the harness, under artifacts/).
# usage: fuzz/replay_sanitized.sh HARNESS DIR
set -u
bin=$1 dir=$2
log=$(mktemp)
trap 'rm -f "$log"' EXIT
files=("$dir"/*)
mkdir -p "$(dirname "$bin")/artifacts"
if ! ASAN_OPTIONS=allocator_may_return_null=1 "$bin" -rss_limit_mb=2048 \
    -artifact_prefix="$(dirname "$bin")/artifacts/replay-" "${files[@]}" > "$log" 2>&1; then
  echo "FAIL: $bin on $dir"
  awk '/ERROR|invariant broken|runtime error/ { on = 1 } on' "$log" | head -n 40 | sed 's/^/    /'
  exit 1
fi
ms=$(sed -n 's/^Executed .* in \([0-9]*\) ms$/\1/p' "$log" | sort -n | tail -1)
[ "$(grep -c '^Executed ' "$log")" = "${#files[@]}" ] || { echo "FAIL: not every input of $dir ran"; cat "$log"; exit 1; }
printf '%-24s%s inputs under the sanitizers, slowest %s ms\n' "" "${#files[@]}" "${ms:-?}"
