"""The web tests' fleet and server: a real fleet (canfleet.Fleet.up, telemetry on a DDS domain of
its own) and a real `canfleet web` reading that domain, its actions going to the fleet's control API."""
from __future__ import annotations

import contextlib
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


@contextlib.contextmanager
def up_with_web(topology: Path, folder: Path, *args: str) -> Generator[str, None, None]:
    """`canfleet up TOPOLOGY ARGS --web 127.0.0.1:0` on private endpoints; yields the page's URL
    (from <state>/logs/web.ready) and checks that the fleet stops cleanly at the end."""
    up = subprocess.Popen([str(find_binaries() / "canfleet"), "up", str(topology), *args,
                           "--control", "tcp://127.0.0.1:0", "--listen", f"unix://{folder / 'b.sock'}",
                           "--ready-file", str(folder / "ready"), "--state-dir", str(folder / "nodes"),
                           "--web", "127.0.0.1:0"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        web_ready = folder / "nodes" / "logs" / "web.ready"
        end = time.monotonic() + 60
        while not web_ready.exists():
            if up.poll() is not None or time.monotonic() > end:
                raise RuntimeError(f"canfleet up --web did not serve (exit {up.poll()})")
            time.sleep(0.1)
        yield web_ready.read_text().split()[1]
    finally:
        up.terminate()
        assert up.wait(timeout=60) == 0


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
