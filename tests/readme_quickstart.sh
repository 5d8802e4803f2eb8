#!/usr/bin/env bash
# The README's C quick start compiles as printed (C99, -Wall -Wextra -Wpedantic -Werror) and runs:
# the first ```c block after "## C quick start", built against the static library.
set -euo pipefail
BUILD=${1:-build}
out="$BUILD/readme"
mkdir -p "$out"
awk '/^## C quick start/ {on = 1} on && /^```c$/ {grab = 1; next} grab && /^```$/ {exit}
     grab {print}' README.md > "$out/quick.c"
[ -s "$out/quick.c" ] || { echo "readme_quickstart: no C block under '## C quick start'" >&2; exit 1; }
${CC:-gcc} -std=c99 -Wall -Wextra -Wpedantic -Werror -Iinclude "$out/quick.c" -o "$out/quick" \
  "$BUILD/libvpds.a" -lm -pthread
# and as C++, the way a C++ engine includes the header and calls the library
${CXX:-g++} -Wall -Wextra -Wpedantic -Werror -Iinclude -x c++ "$out/quick.c" -x none -o "$out/quick_cxx" \
  "$BUILD/libvpds.a" -lm -pthread
line=$("$out/quick")
[ "$("$out/quick_cxx")" = "$line" ] || { echo "readme_quickstart: the C++ build prints otherwise" >&2; exit 1; }
echo "$line" | grep -Eq '^[0-9]+ samples; the first at \(' \
  || { echo "readme_quickstart: unexpected output: $line" >&2; exit 1; }
echo "summary: the README C quick start compiles with -Werror as C99 and as C++ and runs ($line)"
# the surfaces' quick start: the first ```c block after "## Surfaces", the same way
awk '/^## Surfaces/ {on = 1} on && /^```c$/ {grab = 1; next} grab && /^```$/ {exit}
     grab {print}' README.md > "$out/mesh.c"
[ -s "$out/mesh.c" ] || { echo "readme_quickstart: no C block under '## Surfaces'" >&2; exit 1; }
${CC:-gcc} -std=c99 -Wall -Wextra -Wpedantic -Werror -Iinclude "$out/mesh.c" -o "$out/mesh" \
  "$BUILD/libvpds.a" -lm -pthread
${CXX:-g++} -Wall -Wextra -Wpedantic -Werror -Iinclude -x c++ "$out/mesh.c" -x none -o "$out/mesh_cxx" \
  "$BUILD/libvpds.a" -lm -pthread
line=$("$out/mesh")
[ "$("$out/mesh_cxx")" = "$line" ] || { echo "readme_quickstart: the mesh C++ build prints otherwise" >&2; exit 1; }
echo "$line" | grep -Eq '^[0-9]+ samples on the mesh; the first at \(.*\), triangle [01], barycentrics' \
  || { echo "readme_quickstart: unexpected mesh output: $line" >&2; exit 1; }
echo "summary: the README surfaces quick start compiles and runs ($line)"
