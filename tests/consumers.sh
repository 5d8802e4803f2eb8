#!/usr/bin/env bash
# libvpds as engines embed it: the CMake package (install into a prefix, then find_package),
# add_subdirectory and FetchContent of the checkout, and the single file (make amalgamate). Each consumer builds
# the README's C quick start and sample_tool; both must print and write what the Makefile's
# build does, byte for byte, for the golden configurations. Then the single file alone: C99
# and C++ with gcc and clang without a warning, and as a shared object exporting only vpds_*.
set -euo pipefail
BUILD=${1:-build}
root=$(pwd)
out=$BUILD/consumers
rm -rf "$out"
mkdir -p "$out"
quick=$BUILD/readme/quick.c
[ -s "$quick" ] || { echo "consumers: $quick missing (tests/readme_quickstart.sh writes it)" >&2; exit 1; }
mapfile -t configs < <(grep -v '^#' tests/golden/configs.txt)
log=$out/log
run() { "$@" >> "$log" 2>&1 || { echo "consumers: failed: $*" >&2; tail -30 "$log" >&2; exit 1; }; }

# the reference: the Makefile's build
"$BUILD/readme/quick" > "$out/quick.ref"
i=0
for c in "${configs[@]}"; do
  i=$((i + 1))
  # shellcheck disable=SC2086 # a configuration is a list of arguments
  "$BUILD/tests/sample_tool" "$out/ref_$i.bin" $c > /dev/null
done

check() { # name dir: the consumer's outputs against the reference
  local name=$1 dir=$2 i=0
  "$dir/quick" > "$out/quick.$name"
  cmp -s "$out/quick.ref" "$out/quick.$name" \
    || { echo "consumers: $name: the quick start prints '$(cat "$out/quick.$name")'," \
              "the Makefile build '$(cat "$out/quick.ref")'" >&2; exit 1; }
  for c in "${configs[@]}"; do
    i=$((i + 1))
    # shellcheck disable=SC2086
    "$dir/sample_tool" "$out/${name}_$i.bin" $c > /dev/null
    cmp -s "$out/ref_$i.bin" "$out/${name}_$i.bin" \
      || { echo "consumers: $name: other points than the Makefile build for '$c'" >&2; exit 1; }
  done
}

consumer() { # name, then -D options
  local name=$1
  shift
  run cmake -S tests/consumer -B "$out/$name" -DQUICK_START="$root/$quick" -DVPDS_CHECKOUT="$root" "$@"
  run cmake --build "$out/$name" -j 2
  check "$name" "$out/$name"
}

run cmake -S . -B "$out/lib" -DCMAKE_BUILD_TYPE=Release -DVPDS_BUILD_TESTS=OFF -DVPDS_WERROR=ON \
  -DCMAKE_INSTALL_PREFIX="$root/$out/prefix"
run cmake --build "$out/lib" -j 2
run cmake --install "$out/lib"
for f in include/vpds.h lib/libvpds.so.1 lib/libvpds.a lib/cmake/vpds/vpdsConfig.cmake \
         lib/cmake/vpds/vpdsConfigVersion.cmake lib/pkgconfig/vpds.pc; do
  [ -e "$out/prefix/$f" ] || { echo "consumers: the CMake install has no $f" >&2; exit 1; }
done
soname=$(readelf -d "$out/prefix/lib/libvpds.so.1" | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')
[ "$soname" = libvpds.so.1 ] || { echo "consumers: CMake's SONAME is '$soname'" >&2; exit 1; }
consumer package -DVPDS_FROM=package -DCMAKE_PREFIX_PATH="$root/$out/prefix"
# a version the package does not satisfy is refused by find_package
if cmake -S tests/consumer/too_new -B "$out/too_new" -DCMAKE_PREFIX_PATH="$root/$out/prefix" \
     >> "$log" 2>&1; then
  echo "consumers: find_package(vpds 2.0) accepted a 1.x install" >&2; exit 1
fi
consumer subdirectory -DVPDS_FROM=subdirectory
consumer fetchcontent -DVPDS_FROM=fetchcontent
run make --no-print-directory -s amalgamate BUILD="$BUILD"
consumer amalgamated -DVPDS_FROM=amalgamated

single=$BUILD/amalgamated
for cc in "gcc -std=c99" "clang -std=c99" "g++ -x c++" "clang++ -x c++"; do
  run $cc -Wall -Wextra -Wpedantic -Werror -O2 -ffp-contract=off -I"$single" -c "$single/vpds.c" \
    -o "$out/single.o"
done
run gcc -std=c99 -shared -fPIC -fvisibility=hidden -O2 -ffp-contract=off -I"$single" "$single/vpds.c" \
  -o "$out/libsingle.so" -lm -pthread
others=$(nm -D --defined-only "$out/libsingle.so" | awk '{print $3}' | grep -v '^vpds_' || true)
[ -z "$others" ] || { echo "consumers: the single file exports more than vpds_*: $others" >&2; exit 1; }
echo "summary: CMake package (find_package), add_subdirectory, FetchContent and the single file each build the" \
     "quick start and sample_tool with the Makefile build's bytes (${#configs[@]} configurations);" \
     "the single file compiles as C99 and C++ (gcc, clang) without warnings and exports only vpds_*"
