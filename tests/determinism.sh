#!/usr/bin/env bash
# The same seed gives byte-identical points across compilers (gcc, clang), optimisation levels
# (-O0, -O3), sanitizer builds and a build whose indexes swap over more often, and, for every algorithm version N this library has, the
# same bytes as the golden outputs committed for it (tests/golden/vN.sha256, each configuration
# run with desc.algorithm_version = N): a world generated from a seed does not change on
# upgrade. UPDATE_GOLDEN=N rewrites the file of version N only (when that version is new).
set -euo pipefail
out=${1:-build/determinism}
mkdir -p "$out"
current=$(sed -n 's/^#define VPDS_ALGORITHM_VERSION \([0-9]*\).*/\1/p' include/vpds.h)
mapfile -t configs < <(grep -v '^#' tests/golden/configs.txt)
# meshes (tests/tools/mesh_tool.c) exist from version 3 on: their goldens are mesh_vN.sha256
mapfile -t mesh_configs < <(grep -v '^#' tests/golden/mesh_configs.txt)
mesh_first=3
# the last: a domain's search takes a list of at most one sample from the background grid, so
# that a third of its lists come from the kd-tree, built in the middle of the run: the same bytes
variants=("gcc -O0" "gcc -O3" "clang -O0" "clang -O3" "gcc -O1 -fsanitize=address,undefined"
          "gcc -O2 -DVPDSI_GRID_LIST_CAP=1")
# the library's own flags: no FMA contraction, no fast-math
common="-std=c99 -ffp-contract=off -Iinclude"
pids=()
for v in "${variants[@]}"; do # built side by side
  name=$(echo "$v" | tr ' =,' '___')
  command -v "${v%% *}" >/dev/null || { echo "determinism: ${v%% *} missing" >&2; exit 1; }
  { $v $common libvpds/*.c tests/tools/sample_tool.c -lm -pthread -o "$out/tool_$name" &&
    $v $common libvpds/*.c tests/tools/mesh_tool.c -lm -pthread -o "$out/mesh_$name"; } &
  pids+=($!)
done
for p in "${pids[@]}"; do wait "$p" || { echo "determinism: a build failed" >&2; exit 1; }; done
status=0
runs=0
# One family of configurations for one version: TOOL (the binaries' prefix), GOLDEN (the file),
# then the configurations; each is run on every build for the current version, on one otherwise.
check_version() {
  local version=$1 tool=$2 golden=$3 actual ref h i=0 c v name
  shift 3
  actual=$out/actual_$(basename "$golden")
  : > "$actual"
  for c in "$@"; do
    i=$((i + 1))
    ref=""
    local builds=("${variants[@]}")
    [ "$version" = "$current" ] || builds=("${variants[1]}")
    for v in "${builds[@]}"; do
      name=$(echo "$v" | tr ' =,' '___')
      # shellcheck disable=SC2086 # a configuration is a list of arguments
      "$out/${tool}_$name" "$out/out_${tool}_v${version}_${i}_$name.bin" $c "version=$version" > /dev/null ||
        { echo "determinism: version $version, '$c' failed ($v)" >&2; status=1; }
      runs=$((runs + 1))
      h=$(sha256sum "$out/out_${tool}_v${version}_${i}_$name.bin" | cut -d' ' -f1)
      if [ -z "$ref" ]; then ref=$h; elif [ "$h" != "$ref" ]; then
        echo "determinism: version $version, config '$c' differs between builds ($v)" >&2
        status=1
      fi
    done
    echo "$ref  $c" >> "$actual"
  done
  if [ "${UPDATE_GOLDEN:-0}" = "$version" ]; then
    cp "$actual" "$golden"
    echo "golden outputs of version $version rewritten ($golden)"
  fi
  if [ ! -f "$golden" ]; then
    echo "determinism: $golden is missing (UPDATE_GOLDEN=$version writes it)" >&2
    status=1
  elif ! diff -u "$golden" "$actual"; then
    echo "determinism: output differs from the golden outputs of algorithm version $version ($golden)" >&2
    status=1
  fi
}

for version in $(seq 1 "$current"); do
  check_version "$version" tool "tests/golden/v$version.sha256" "${configs[@]}"
  if [ "$version" -ge "$mesh_first" ]; then
    check_version "$version" mesh "tests/golden/mesh_v$version.sha256" "${mesh_configs[@]}"
  fi
done
[ $status = 0 ] && echo "summary: versions 1..$current, ${#configs[@]} configurations each, meshes from version $mesh_first on ${#mesh_configs[@]} more ($runs runs: version $current on ${#variants[@]} builds, identical bytes; older versions on ${variants[1]}), matching the golden outputs"
exit $status
