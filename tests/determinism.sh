#!/usr/bin/env bash
# The same seed gives byte-identical points across compilers (gcc, clang), optimisation levels
# (-O0, -O3) and sanitizer builds, and the same bytes as the golden outputs committed for
# algorithm version 1 (tests/golden/v1.sha256). UPDATE_GOLDEN=1 rewrites them (only when
# VPDS_ALGORITHM_VERSION changes).
set -euo pipefail
out=${1:-build/determinism}
mkdir -p "$out"
golden=tests/golden/v1.sha256
configs=(
  "2 smaller const 0.02 1 0 1"
  "1 bigger ramp 0 2 0 1"
  "3 prior ramp 0 3 0.02 0.32"
  "2 current radial 0 4 0.5 0.6"
  "4 smaller const 0.2 5 0 1"
  "2 smaller mild 0 6 0 1 0 1"
)
variants=("gcc -O0" "gcc -O3" "clang -O0" "clang -O3" "gcc -O1 -fsanitize=address,undefined")
# the library's own flags: no FMA contraction, no fast-math
common="-std=c99 -ffp-contract=off -Iinclude"
for v in "${variants[@]}"; do
  name=$(echo "$v" | tr ' =,' '___')
  command -v "${v%% *}" >/dev/null || { echo "determinism: ${v%% *} missing" >&2; exit 1; }
  $v $common libvpds/*.c tests/tools/sample_tool.c -lm -o "$out/tool_$name"
done
status=0
: > "$out/actual.sha256"
i=0
for c in "${configs[@]}"; do
  i=$((i + 1))
  ref=""
  for v in "${variants[@]}"; do
    name=$(echo "$v" | tr ' =,' '___')
    "$out/tool_$name" "$out/out_${i}_$name.bin" $c > /dev/null
    h=$(sha256sum "$out/out_${i}_$name.bin" | cut -d' ' -f1)
    if [ -z "$ref" ]; then ref=$h; elif [ "$h" != "$ref" ]; then
      echo "determinism: config '$c' differs between builds ($v)" >&2; status=1
    fi
  done
  echo "$ref  $c" >> "$out/actual.sha256"
done
if [ "${UPDATE_GOLDEN:-0}" = 1 ]; then cp "$out/actual.sha256" "$golden"; echo "golden outputs rewritten"; fi
if ! diff -u "$golden" "$out/actual.sha256"; then
  echo "determinism: output differs from the golden outputs of algorithm version 1" >&2; status=1
fi
[ $status = 0 ] && echo "summary: ${#configs[@]} configurations, ${#variants[@]} builds each, identical bytes, matching the golden outputs"
exit $status
