#!/usr/bin/env bash
# Creates the project's Python virtualenv (.venv) with pinned python-can, canopen and pytest from
# PyPI, used by the socketcand system test (python-can's `socketcand` interface) and the
# conformance suite (tests/conformance/: python-canopen as an independent CANopen master, run by
# pytest). Idempotent: when the pinned versions
# are installed it does nothing and needs no network.
#
# Usage: scripts/python-env.sh          prints the interpreter path (.venv/bin/python)
#
# The venv is made with Debian's /usr/bin/python3 (package python3-venv), never with another
# python first on PATH (pyenv shims), so it is the same on every Debian 12 machine.
#
# Pins: python-can 4.6.1, not Debian's python3-can 4.1.0. 4.1.0's socketcand client flags every
# received frame as extended, writes 29-bit ids without leading zeros (small ones are then sent as
# 11-bit) and loses a frame split across two of its 1024-byte reads; 4.6.1 fixes all three
# (canfleet's endpoint also pads its raw-mode records to 64 bytes, so 4.1.0 does not lose frames).
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON_CAN_VERSION=4.6.1
CANOPEN_VERSION=2.4.1
PYTEST_VERSION=8.3.5
base_python=/usr/bin/python3
venv=.venv

if [ ! -x "$base_python" ]; then
  echo "python-env: $base_python not found (apt-get install python3 python3-venv)" >&2
  exit 1
fi

mkdir -p "$venv"
exec 9>"$venv/.lock"  # several test processes may ask at once
flock 9

installed() {
  [ -x "$venv/bin/python" ] && "$venv/bin/python" - "$PYTHON_CAN_VERSION" "$CANOPEN_VERSION" "$PYTEST_VERSION" <<'PY' 2>/dev/null
import sys
from importlib.metadata import version, PackageNotFoundError
try:
    ok = (version("python-can") == sys.argv[1] and version("canopen") == sys.argv[2]
          and version("pytest") == sys.argv[3])
except PackageNotFoundError:
    ok = False
sys.exit(0 if ok else 1)
PY
}

if ! installed; then
  if [ ! -x "$venv/bin/python" ]; then
    "$base_python" -m venv "$venv" >&2
  fi
  echo "python-env: installing python-can==$PYTHON_CAN_VERSION canopen==$CANOPEN_VERSION" \
    "pytest==$PYTEST_VERSION into $venv" >&2
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    "python-can==$PYTHON_CAN_VERSION" "canopen==$CANOPEN_VERSION" "pytest==$PYTEST_VERSION" >&2
  installed || {
    echo "python-env: the pinned versions are not importable after installing" >&2
    exit 1
  }
fi
echo "$PWD/$venv/bin/python"
