#!/usr/bin/env bash
# The shared object's contract: only vpds_* exported, SONAME libvpds.so.1, the header compiles as
# C99 -pedantic and as C++, and an installed copy is found through pkg-config and works.
set -euo pipefail
BUILD=${1:-build}
fail() { echo "abi_check: $*" >&2; exit 1; }

exported=$(nm -D --defined-only "$BUILD/libvpds.so" | awk '$2 ~ /^[TDBR]$/ {print $3}' | sed 's/@.*//')
[ -n "$exported" ] || fail "no exported symbols"
others=$(echo "$exported" | grep -v '^vpds_' || true)
[ -z "$others" ] || fail "exported symbols without the vpds_ prefix: $others"
echo "exported: $(echo "$exported" | wc -l) symbols, all vpds_*"

soname=$(readelf -d "$BUILD/libvpds.so" | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')
[ "$soname" = "libvpds.so.1" ] || fail "SONAME is '$soname'"
echo "SONAME: $soname"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/use.c" <<'C'
#include <vpds.h>
#include <stdio.h>
int main(void)
{
    vpds_desc d = vpds_default_desc();
    vpds_sampler *s = NULL;
    d.radius = 0.05;
    if (vpds_create(&d, &s) != VPDS_OK || vpds_run(s) != VPDS_OK) return 1;
    printf("%zu\n", vpds_count(s));
    vpds_destroy(s);
    return 0;
}
C
cp "$tmp/use.c" "$tmp/use.cpp"
cc -std=c99 -Wall -Wextra -Wpedantic -Werror -Iinclude -c "$tmp/use.c" -o "$tmp/use_c.o"
c++ -std=c++11 -Wall -Wextra -Wpedantic -Werror -Iinclude "$tmp/use.cpp" -o "$tmp/use_cpp" -L"$BUILD" -lvpds
n_cpp=$(LD_LIBRARY_PATH="$BUILD" "$tmp/use_cpp")
echo "C++ translation unit: built and ran ($n_cpp samples)"

make --no-print-directory -s install PREFIX="$tmp/prefix" BUILD="$BUILD" >/dev/null
cc -std=c99 "$tmp/use.c" -o "$tmp/use_installed" $(PKG_CONFIG_PATH="$tmp/prefix/lib/pkgconfig" pkg-config --cflags --libs vpds)
n_inst=$(LD_LIBRARY_PATH="$tmp/prefix/lib" "$tmp/use_installed")
[ "$n_inst" = "$n_cpp" ] || fail "installed copy gave $n_inst samples, the build $n_cpp"
[ -L "$tmp/prefix/lib/libvpds.so.1" ] || fail "libvpds.so.1 not installed"
echo "make install + pkg-config: built and ran ($n_inst samples)"
echo "summary: $(echo "$exported" | wc -l) symbols exported, all vpds_*; SONAME $soname; the header as C++; make install + pkg-config"
