#!/usr/bin/env bash
# Creates the project's Python virtualenv (.venv) with pinned python-can, canopen, pytest and
# protobuf from PyPI, used by the socketcand system test (python-can's `socketcand` interface), the
# conformance suite (tests/conformance/: python-canopen as an independent CANopen master, run by
# pytest) and the canfleet Python package (python/, installed editable: python/README.md), whose
# protobuf modules are generated from the repository's .proto files at install time.
# Idempotent: when the pinned versions are installed and the package's build inputs (pyproject,
# setup.py, the .proto files, the wire protocol version) are unchanged it does nothing and needs no
# network.
#
# Usage: scripts/python-env.sh          prints the interpreter path (.venv/bin/python)
# Exit codes: 0 ready; 75 PyPI could not be reached for the pinned packages (callers skip, saying
# so); 1 anything else, above all the canfleet package failing to build or import (callers fail:
# that is our bug, not the machine's).
#
# The venv is made with Debian's /usr/bin/python3 (package python3-venv), never with another
# python first on PATH (pyenv shims), so it is the same on every Debian 12 machine.
#
# Pins: python-can 4.6.1, not Debian's python3-can 4.1.0. 4.1.0's socketcand client flags every
# received frame as extended, writes 29-bit ids without leading zeros (small ones are then sent as
# 11-bit) and loses a frame split across two of its 1024-byte reads; 4.6.1 fixes all three
# (canfleet's endpoint also pads its raw-mode records to 64 bytes, so 4.1.0 does not lose frames).
# protobuf 4.21.12: the Python runtime of Debian 12's protoc 3.21.12, which generates the package's
# modules (python/setup.py). setuptools and wheel build the package without build isolation (no
# download per install). mypy and types-protobuf check the package's type hints (python/tests/test_types.py).
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON_CAN_VERSION=4.6.1
CANOPEN_VERSION=2.4.1
PYTEST_VERSION=8.3.5
PROTOBUF_VERSION=4.21.12
SETUPTOOLS_VERSION=69.5.1
WHEEL_VERSION=0.43.0
MYPY_VERSION=1.10.0
TYPES_PROTOBUF_VERSION=4.21.0.7
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
  [ -x "$venv/bin/python" ] && "$venv/bin/python" - "$PYTHON_CAN_VERSION" "$CANOPEN_VERSION" "$PYTEST_VERSION" \
    "$PROTOBUF_VERSION" "$MYPY_VERSION" <<'PY' 2>/dev/null
import sys
from importlib.metadata import version, PackageNotFoundError
try:
    ok = (version("python-can") == sys.argv[1] and version("canopen") == sys.argv[2]
          and version("pytest") == sys.argv[3] and version("protobuf") == sys.argv[4]
          and version("mypy") == sys.argv[5])
except PackageNotFoundError:
    ok = False
sys.exit(0 if ok else 1)
PY
}

# What the installed canfleet package was generated from: a change of any of these reinstalls it.
package_inputs() {
  cat python/pyproject.toml python/setup.py bus/wire/canfleet_wire.proto \
    orchestrator/control/canfleet_control.proto bus/wire/messages.hpp | sha256sum | cut -d' ' -f1
}
package_stamp="$venv/.canfleet-package"

if ! installed; then
  if [ ! -x "$venv/bin/python" ]; then
    "$base_python" -m venv "$venv" >&2
  fi
  echo "python-env: installing python-can==$PYTHON_CAN_VERSION canopen==$CANOPEN_VERSION" \
    "pytest==$PYTEST_VERSION protobuf==$PROTOBUF_VERSION into $venv" >&2
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    "python-can==$PYTHON_CAN_VERSION" "canopen==$CANOPEN_VERSION" "pytest==$PYTEST_VERSION" \
    "protobuf==$PROTOBUF_VERSION" "setuptools==$SETUPTOOLS_VERSION" "wheel==$WHEEL_VERSION" \
    "mypy==$MYPY_VERSION" "types-protobuf==$TYPES_PROTOBUF_VERSION" >&2 || {
    # Pinned releases from PyPI: what fails here is the network (a machine that cannot reach PyPI),
    # 75 (EX_TEMPFAIL) so that the suites say "skipped: no venv" rather than fail.
    echo "python-env: pip could not install the pinned packages (is PyPI reachable?)" >&2
    exit 75
  }
  installed || {
    echo "python-env: the pinned versions are not importable after installing" >&2
    exit 1
  }
fi
inputs="$(package_inputs)"
if [ "$(cat "$package_stamp" 2>/dev/null)" != "$inputs" ] || ! "$venv/bin/python" -c 'import canfleet._proto' 2>/dev/null; then
  echo "python-env: installing the canfleet package (python/, editable) into $venv" >&2
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-build-isolation --no-deps \
    --editable ./python >&2
  "$venv/bin/python" -c 'import canfleet._proto' || {
    echo "python-env: the canfleet package is not importable after installing" >&2
    exit 1
  }
  echo "$inputs" > "$package_stamp"
fi
echo "$PWD/$venv/bin/python"
