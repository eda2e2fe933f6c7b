"""The web tests' fleet and server: a real fleet (canfleet.Fleet.up, telemetry on a DDS domain of
its own) and a real `canfleet web` reading that domain, its actions going to the fleet's control API."""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Dict, Generator, List

import pytest

from canfleet import Fleet
from canfleet.fleet import find_binaries

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
PAIR = REPO / "python" / "tests" / "topologies" / "pair.textproto"
DOMAIN = os.environ.setdefault("CANFLEET_DDS_DOMAIN", "93")  # this suite's own DDS domain
sys.path.insert(0, str(HERE))


def start_web(*args: str, control: str = "", folder: Path) -> Dict[str, object]:
    """`canfleet web ARGS` until the test ends; returns url, token, proc."""
    ready = folder / f"web-{time.monotonic_ns()}.ready"
    cmd = [str(find_binaries() / "canfleet")] + (["--control", control] if control else []) + \
          ["web", "--ready-file", str(ready), *args]
    log = open(folder / (ready.name + ".log"), "wb")
    proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
    end = time.monotonic() + 30
    while not ready.exists():
        if proc.poll() is not None or time.monotonic() > end:
            proc.kill()
            raise RuntimeError(f"canfleet web did not start: {(folder / (ready.name + '.log')).read_text()}")
        time.sleep(0.05)
    values = dict(line.split(" ", 1) for line in ready.read_text().splitlines())
    return {"url": values["url"], "token": values.get("token", ""), "proc": proc}


@pytest.fixture
def fleet(tmp_path: Path) -> Generator[Fleet, None, None]:
    with Fleet.up(PAIR, telemetry=True, state_dir=tmp_path / "fleet") as f:
        yield f


@pytest.fixture
def webs(tmp_path: Path) -> Generator[List[Dict[str, object]], None, None]:
    started: List[Dict[str, object]] = []
    yield started
    for web in started:
        proc = web["proc"]
        assert isinstance(proc, subprocess.Popen)
        proc.terminate()
        assert proc.wait(timeout=20) == 0, "canfleet web must stop cleanly on SIGTERM"
