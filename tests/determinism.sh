#!/usr/bin/env bash
# The same seed gives byte-identical points across compilers (gcc, clang), optimisation levels
# (-O0, -O3) and sanitizer builds, and, for every algorithm version N this library has, the
# same bytes as the golden outputs committed for it (tests/golden/vN.sha256, each configuration
# run with desc.algorithm_version = N): a world generated from a seed does not change on
# upgrade. UPDATE_GOLDEN=N rewrites the file of version N only (when that version is new).
set -euo pipefail
out=${1:-build/determinism}
mkdir -p "$out"
current=$(sed -n 's/^#define VPDS_ALGORITHM_VERSION \([0-9]*\).*/\1/p' include/vpds.h)
mapfile -t configs < <(grep -v '^#' tests/golden/configs.txt)
variants=("gcc -O0" "gcc -O3" "clang -O0" "clang -O3" "gcc -O1 -fsanitize=address,undefined")
# the library's own flags: no FMA contraction, no fast-math
common="-std=c99 -ffp-contract=off -Iinclude"
pids=()
for v in "${variants[@]}"; do # built side by side
  name=$(echo "$v" | tr ' =,' '___')
  command -v "${v%% *}" >/dev/null || { echo "determinism: ${v%% *} missing" >&2; exit 1; }
  $v $common libvpds/*.c tests/tools/sample_tool.c -lm -pthread -o "$out/tool_$name" &
  pids+=($!)
done
for p in "${pids[@]}"; do wait "$p" || { echo "determinism: a build failed" >&2; exit 1; }; done
status=0
runs=0
for version in $(seq 1 "$current"); do
  golden=tests/golden/v$version.sha256
  actual=$out/actual_v$version.sha256
  : > "$actual"
  i=0
  for c in "${configs[@]}"; do
    i=$((i + 1))
    ref=""
    # the current version on every build; an older one's goldens on one (the builds agree)
    builds=("${variants[@]}")
    [ "$version" = "$current" ] || builds=("${variants[1]}")
    for v in "${builds[@]}"; do
      name=$(echo "$v" | tr ' =,' '___')
      # shellcheck disable=SC2086 # a configuration is a list of arguments
      "$out/tool_$name" "$out/out_v${version}_${i}_$name.bin" $c "version=$version" > /dev/null
      runs=$((runs + 1))
      h=$(sha256sum "$out/out_v${version}_${i}_$name.bin" | cut -d' ' -f1)
      if [ -z "$ref" ]; then ref=$h; elif [ "$h" != "$ref" ]; then
        echo "determinism: version $version, config '$c' differs between builds ($v)" >&2
        status=1
      fi
    done
    echo "$ref  $c" >> "$actual"
  done
  if [ "${UPDATE_GOLDEN:-0}" = "$version" ]; then
    cp "$actual" "$golden"
    echo "golden outputs of version $version rewritten"
  fi
  if [ ! -f "$golden" ]; then
    echo "determinism: $golden is missing (UPDATE_GOLDEN=$version writes it)" >&2
    status=1
  elif ! diff -u "$golden" "$actual"; then
    echo "determinism: output differs from the golden outputs of algorithm version $version" >&2
    status=1
  fi
done
[ $status = 0 ] && echo "summary: versions 1..$current, ${#configs[@]} configurations each ($runs runs: version $current on ${#variants[@]} builds, identical bytes; older versions on ${variants[1]}), matching the golden outputs"
exit $status
