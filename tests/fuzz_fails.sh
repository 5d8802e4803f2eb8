#!/usr/bin/env bash
# `make fuzz` must fail when a harness crashes, leaks or hangs: nonzero status, the harness named
# FAIL with libFuzzer's report, its input kept under BUILD/ (none in the repository's root), and
# the harnesses after it still run. The failing harnesses are in tests/fuzz_bad/, fed to the very
# recipe `make fuzz` and `make check-fuzz` use through FUZZ_DIR, FUZZ_OUT and FUZZERS.
# usage: tests/fuzz_fails.sh [BUILD]
set -u
build=${1:-build}
out=$build/fuzz_bad
make=${MAKE:-make}
status=0
fail() { echo "fuzz_fails: $*" >&2; status=1; }
rm -rf "$out"
mkdir -p "$out"
stray() { ls -d crash-* leak-* timeout-* oom-* slow-unit-* 2> /dev/null | sort; }
before=$(stray)
# harness, the artifact libFuzzer names for its finding, what the report says
for c in "abort crash deadly signal" "leak leak LeakSanitizer" "hang timeout timeout after"; do
  set -- $c
  bad=$1 kind=$2
  shift 2
  what="$*"
  log=$out/make_$bad.log
  if "$make" --no-print-directory fuzz BUILD="$build" FUZZ_DIR=tests/fuzz_bad FUZZ_OUT="$out" \
    FUZZERS="$bad ok" FUZZ_SECONDS=3 FUZZ_TIMEOUT=2 FUZZ_CORPUS=fresh > "$log" 2>&1; then
    fail "make fuzz exited 0 with fuzz_$bad (log $log)"
  fi
  grep -q "^fuzz_$bad .*: FAIL" "$log" || fail "fuzz_$bad not reported FAIL (log $log)"
  grep -q "$what" "$log" || fail "fuzz_$bad: no '$what' in the report shown (log $log)"
  grep -q "^fuzz_ok .*: OK$" "$log" || fail "fuzz_ok, after fuzz_$bad, not reported OK (log $log)"
  grep -q "^fuzz: FAILED: fuzz_$bad (" "$log" || fail "the closing line does not name fuzz_$bad (log $log)"
  ls "$out/artifacts/$bad-$kind-"* > /dev/null 2>&1 ||
    fail "no $out/artifacts/$bad-$kind-* written (log $log)"
  [ $status = 0 ] && echo "fuzz_fails: fuzz_$bad fails make fuzz; its input is in $(ls "$out/artifacts/$bad-$kind-"* | head -1)"
done
# the sanitized replay of fuzz/slow/ (make check-fuzz) fails on a harness that crashes, leaks or
# hangs too, and on a directory without inputs
mkdir -p "$out/inputs" "$out/no_inputs/sub"
printf 'xx' > "$out/inputs/one" # the bad harnesses misbehave on two bytes
for c in "abort deadly signal" "leak LeakSanitizer" "hang timeout after"; do
  set -- $c
  bad=$1
  shift
  what="$*"
  log=$out/replay_$bad.log
  if bash fuzz/replay_sanitized.sh "$out/fuzz_$bad" "$out/inputs" 2 > "$log" 2>&1; then
    fail "fuzz/replay_sanitized.sh exited 0 with fuzz_$bad (log $log)"
  elif ! grep -q "$what" "$log"; then
    fail "fuzz/replay_sanitized.sh did not show fuzz_$bad's report (log $log)"
  else
    echo "fuzz_fails: fuzz_$bad fails fuzz/replay_sanitized.sh"
  fi
done
if bash fuzz/replay_sanitized.sh "$out/fuzz_ok" "$out/no_inputs" > "$out/replay_none.log" 2>&1; then
  fail "fuzz/replay_sanitized.sh exited 0 on a directory without inputs"
fi
[ "$(stray)" = "$before" ] || fail "artifacts written to the repository's root: $(stray)"
exit $status
