#!/usr/bin/env bash
# The project's Python environment (make demo, make test, make bench): a virtual environment
# without the system's site-packages, so a green run cannot lean on what an earlier one left.
set -euo pipefail
venv=${1:?usage: tools/venv.sh DIR}
py=${PYTHON:-python3}
if ! "$py" -m venv "$venv" 2>/dev/null; then
  # Debian's python3 without python3-venv: virtualenv from PyPI does the same job
  rm -rf "$venv"
  "$py" -m pip install -q --disable-pip-version-check --user virtualenv
  "$py" -m virtualenv -q "$venv"
fi
"$venv/bin/python" -m pip --version >/dev/null
