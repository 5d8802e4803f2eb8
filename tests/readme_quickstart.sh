#!/usr/bin/env bash
# The README's C quick starts compile as printed (C99, -Wall -Wextra -Wpedantic -Werror, and as
# C++) and run: the first ```c block after "## C quick start" and after "## Surfaces", built
# against the static library, each printing the line its pattern expects.
set -euo pipefail
BUILD=${1:-build}
out="$BUILD/readme"
mkdir -p "$out"

# quick_start HEADING NAME PATTERN: extract, build both ways, run, compare; prints the line
quick_start() {
  local heading=$1 name=$2 pattern=$3 line
  awk -v h="^## $heading" '$0 ~ h {on = 1} on && /^```c$/ {grab = 1; next} grab && /^```$/ {exit}
       grab {print}' README.md > "$out/$name.c"
  [ -s "$out/$name.c" ] || { echo "readme_quickstart: no C block under '## $heading'" >&2; exit 1; }
  ${CC:-gcc} -std=c99 -Wall -Wextra -Wpedantic -Werror -Iinclude "$out/$name.c" -o "$out/$name" \
    "$BUILD/libvpds.a" -lm -pthread
  # and as C++, the way a C++ engine includes the header and calls the library
  ${CXX:-g++} -Wall -Wextra -Wpedantic -Werror -Iinclude -x c++ "$out/$name.c" -x none -o "$out/${name}_cxx" \
    "$BUILD/libvpds.a" -lm -pthread
  line=$("$out/$name")
  [ "$("$out/${name}_cxx")" = "$line" ] || { echo "readme_quickstart: the $name C++ build prints otherwise" >&2; exit 1; }
  echo "$line" | grep -Eq "$pattern" || { echo "readme_quickstart: unexpected $name output: $line" >&2; exit 1; }
  echo "$line"
}

line=$(quick_start "C quick start" quick '^[0-9]+ samples; the first at \(')
echo "summary: the README C quick start compiles with -Werror as C99 and as C++ and runs ($line)"
line=$(quick_start "Surfaces" mesh '^[0-9]+ samples on the mesh; the first at \(.*\), triangle [01], barycentrics')
echo "summary: the README surfaces quick start compiles and runs ($line)"
