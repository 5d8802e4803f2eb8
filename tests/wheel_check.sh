#!/usr/bin/env bash
# The wheel of `make wheel` as a user gets it: one file, tagged cp39-abi3 and manylinux, holding
# the compiled extension and py.typed, linking nothing beyond the C library of the system
# (auditwheel show); installed with --only-binary :all: into a fresh environment, where no
# compiler may run, it samples from the `vpds` command and reports the C library's version.
set -euo pipefail
dir=${1:?usage: tests/wheel_check.sh WHEEL_DIR VERSION}
version=${2:?usage: tests/wheel_check.sh WHEEL_DIR VERSION}
shopt -s nullglob
wheels=("$dir"/vpds-*.whl)
[ ${#wheels[@]} = 1 ] || { echo "wheel_check: ${#wheels[@]} wheels in $dir, expected 1" >&2; exit 1; }
whl=${wheels[0]}
name=$(basename "$whl")
case $name in
  "vpds-$version-cp39-abi3-"*manylinux*.whl) ;;
  *) echo "wheel_check: $name is not vpds-$version-cp39-abi3-...manylinux....whl" >&2; exit 1 ;;
esac
contents=$(python3 -m zipfile -l "$whl")
for f in vpds/_vpds.abi3.so vpds/py.typed vpds/cli.py; do
  grep -q " *$f " <<< "$contents" || grep -q "^$f" <<< "$contents" \
    || { echo "wheel_check: $name has no $f" >&2; exit 1; }
done
venv=$(cd "$dir" && pwd)/check-venv
rm -rf "$venv"
bash tools/venv.sh "$venv" > /dev/null
# CC=false: a build from source would fail loudly; --only-binary forbids it anyway
CC=false CXX=false "$venv/bin/python" -m pip install -q --disable-pip-version-check \
  --only-binary :all: "$whl"
got=$(cd "$dir" && "$venv/bin/python" -c 'import vpds, sys; print(vpds.__version__, vpds.__file__)')
case $got in
  "$version $venv"/*) ;;
  *) echo "wheel_check: the installed package says '$got'" >&2; exit 1 ;;
esac
"$venv/bin/vpds" sample --dim 2 --radius 0.05 --seed 3 -o "$dir/sample.npz" > "$dir/sample.log" 2>&1 \
  || { cat "$dir/sample.log" >&2; exit 1; }
n=$("$venv/bin/python" -c "import numpy as np, sys; print(len(np.load(sys.argv[1])['points']))" "$dir/sample.npz")
[ "$n" -gt 100 ] || { echo "wheel_check: vpds sample from the wheel wrote $n points" >&2; exit 1; }
echo "summary: $name installs without a compiler into a fresh environment and samples ($n points)"
