"""The examples users copy (python/examples/) run as users run them, each in its own process, and
say what they checked with their simulated and wall time."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("example, ok", [
    ("heartbeat_loss.py", "heartbeat_loss: ok"),
    ("rpdo_timeout.py", "rpdo_timeout: ok"),
    ("soak.py", "soak: ok"),  # ten simulated minutes with 30 % of quad-5's frames dropped
])
def test_example_runs_and_checks_what_it_says(example: str, ok: str) -> None:
    run = subprocess.run([sys.executable, str(EXAMPLES / example)], capture_output=True, text=True, timeout=600,
                         cwd=EXAMPLES)
    assert run.returncode == 0, run.stdout + run.stderr
    assert ok in run.stdout, run.stdout
    assert "s simulated in" in run.stdout and "s wall" in run.stdout
