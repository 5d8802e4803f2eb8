#!/usr/bin/env bash
# Everything `make test` needs beyond gcc, make and python3: Debian packages, then PyPI packages.
set -euo pipefail
cd "$(dirname "$0")/.."
missing=()
for pkg in libflann-dev clang libclang-rt-14-dev valgrind pkg-config; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
python3 -m pip install -q --disable-pip-version-check -r tests/requirements.txt
