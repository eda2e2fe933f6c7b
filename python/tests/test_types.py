"""The package's type hints hold: mypy --strict (pyproject.toml [tool.mypy]) on canfleet/, with the
stubs protoc generated for the messages. Pinned mypy in scripts/python-env.sh."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest


def test_the_package_type_checks_strictly() -> None:
    pytest.importorskip("mypy", reason="mypy is not installed (scripts/python-env.sh pins it)")
    package = Path(__file__).resolve().parents[1]
    result = subprocess.run([sys.executable, "-m", "mypy", "--no-incremental"], cwd=package,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
