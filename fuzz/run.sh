#!/usr/bin/env bash
# Runs libFuzzer harnesses one after another and says, per harness, one line: executions,
# exec/s and OK or FAIL. A crash, an invariant broken, a leak, an input slower than the
# per-input timeout or one above the memory limit is a FAIL: its libFuzzer report is shown,
# its input is written under OUT/artifacts/ and the script exits 1 after the last harness.
#
# usage: fuzz/run.sh OUT SECONDS TIMEOUT RSS_MB SEEDS CORPUS HARNESS...
#   OUT      directory of the fuzz_<harness> binaries; logs and artifacts go there too
#   SECONDS  fuzzing time per harness (-max_total_time); TIMEOUT seconds per input (-timeout)
#   RSS_MB   memory limit (-rss_limit_mb, also the largest single allocation)
#   SEEDS    directory of the committed seed corpora, SEEDS/<harness> (may be missing)
#   CORPUS   "grow": new inputs go to OUT/corpus_<harness> and stay for the next run;
#            "fresh": they go to a directory emptied first, so that a run starts from the
#            seeds alone and takes the same time every time (make check-fuzz)
# FUZZ_JOBS harnesses run side by side (default: the cores); their reports print in order.
set -u
jobs=${FUZZ_JOBS:-$(nproc 2>/dev/null || echo 1)}
out=$1 seconds=$2 timeout=$3 rss=$4 seeds=$5 corpus=$6
shift 6
# one input may run up to TIMEOUT past the budget, and the seeds run before it starts
wall=$((seconds + 2 * timeout + 60))
mkdir -p "$out/artifacts"

# One harness: its one-line summary (and on failure libFuzzer's report) into
# OUT/fuzz_F.report; OUT/fuzz_F.failed exists when it failed.
fuzz_one() {
  local f=$1 bin=$out/fuzz_$1 log=$out/fuzz_$1.log dir=$out/corpus_$1 report=$out/fuzz_$1.report
  local seed=() start rc took runs rate slow summary why
  rm -f "$out/fuzz_$f.failed"
  [ "$corpus" = fresh ] && dir=$out/check_corpus_$f && rm -rf "$dir"
  mkdir -p "$dir"
  [ -d "$seeds/$f" ] && seed=("$seeds/$f")
  start=$(date +%s)
  # allocator_may_return_null: the harnesses test the library's out-of-memory paths
  ASAN_OPTIONS=allocator_may_return_null=1 timeout -k 10 "$wall" "$bin" \
    -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb="$rss" -max_len=512 \
    -print_final_stats=1 -artifact_prefix="$out/artifacts/$f-" "$dir" "${seed[@]}" > "$log" 2>&1
  rc=$?
  took=$(($(date +%s) - start))
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  slow=$(sed -n 's/^stat::slowest_unit_time_sec: *//p' "$log" | tail -1)
  summary=$(printf 'fuzz_%-9s %9s runs in %3d s, %6s exec/s' "$f" "${runs:-?}" "$took" "${rate:-?}")
  [ "${slow:-0}" -gt 0 ] 2> /dev/null && summary="$summary, slowest input $slow s"
  if [ $rc = 0 ] && [ -n "$runs" ]; then
    echo "$summary: OK" > "$report"
    return
  fi
  touch "$out/fuzz_$f.failed"
  case $rc in
    124 | 137) why="did not stop within $wall s" ;;
    0) why="no statistics in the log" ;;
    *) why="exit status $rc" ;;
  esac
  {
    echo "$summary: FAIL ($why; full log $log)"
    # the report: from the first error line on (sanitizer, libFuzzer, harness invariant),
    # without the frames of libFuzzer's own loop and of the C runtime
    awk '/ERROR|invariant broken|runtime error/ { on = 1 } on' "$log" |
      grep -Ev ' in (fuzzer::|__sanitizer_print_stack_trace|__libc_start|_start |main )' |
      head -n 40 | sed 's/^/    /'
    sed -n 's/.*Test unit written to \(.*\)/    artifact: \1/p' "$log"
  } > "$report"
}

running=0
for f in "$@"; do
  fuzz_one "$f" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
done
wait
failed=()
for f in "$@"; do
  if [ -f "$out/fuzz_$f.report" ]; then cat "$out/fuzz_$f.report"; else echo "fuzz_$f: FAIL (no report)"; failed+=("fuzz_$f"); fi
  [ -f "$out/fuzz_$f.failed" ] && failed+=("fuzz_$f")
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]} (replay an artifact with $out/fuzz_<harness> ARTIFACT)"
  exit 1
fi
