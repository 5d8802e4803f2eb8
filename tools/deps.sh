#!/usr/bin/env bash
# What `make test` needs beyond make demo's: Debian packages (as root or with sudo), then the
# PyPI packages of tests/requirements.txt into the project's environment (the python given).
set -euo pipefail
cd "$(dirname "$0")/.."
py=${1:?usage: tools/deps.sh PYTHON}
missing=()
for pkg in libflann-dev clang libclang-rt-14-dev valgrind pkg-config cmake; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "deps: apt-get install ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
echo "deps: pip install -r tests/requirements.txt into $(dirname "$(dirname "$py")")"
"$py" -m pip install -q --disable-pip-version-check -r tests/requirements.txt
