"""Processes and pytest: no fleet process outlives the test process (SIGKILL, Ctrl-C), a node that
dies fails its test with its exit status, and a failing test's report carries the fleet's status,
log and capture paths (terminal and JUnit). Each test runs an inner pytest on the plugin."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import List

import pytest

from helpers import PAIR, all_gone, alive, wait_until

HOLD = '''
import os, threading
from pathlib import Path
import pytest

@pytest.mark.topology(os.environ["TOPOLOGY"])
def test_hold(fleet):
    pids = [fleet.pid] + [n.pid for n in fleet.status().nodes if n.pid]
    Path(os.environ["PIDS_FILE"]).write_text(" ".join(map(str, pids)))
    threading.Event().wait()  # until the outer test kills or interrupts this process
'''

REPORTS = '''
import os, signal, time
import pytest

TOPOLOGY = os.environ["TOPOLOGY"]

@pytest.mark.topology(TOPOLOGY)
def test_node_dies(fleet):
    os.kill(fleet.node("io-21").status().pid, signal.SIGKILL)
    deadline = time.monotonic() + 30
    while not fleet.dead_nodes() and time.monotonic() < deadline:
        time.sleep(0.02)
    # the body passes: the plugin fails the test

@pytest.mark.topology(TOPOLOGY)
def test_fails(fleet):
    fleet.capture("can0")
    assert fleet.node("quad-5").status().nmt_state == "a state no node has"

@pytest.mark.topology(TOPOLOGY)
def test_passes(fleet):
    assert fleet.node("quad-5").status().process == "running"
'''


def inner_pytest(tmp_path: Path, source: str, *args: str) -> "subprocess.Popen[str]":
    test = tmp_path / "test_inner.py"
    test.write_text(source)
    # TMPDIR: the inner fleets' state folders go below tmp_path, so that a killed run (which
    # removes nothing) leaves them where pytest cleans up.
    env = dict(os.environ, TOPOLOGY=str(PAIR), PIDS_FILE=str(tmp_path / "pids"), PYTHONDONTWRITEBYTECODE="1",
               TMPDIR=str(tmp_path))
    return subprocess.Popen([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-rA", str(test), *args],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def held_pids(tmp_path: Path, inner: "subprocess.Popen[str]") -> List[int]:
    pids_file = tmp_path / "pids"
    got = wait_until(lambda: inner.poll() is not None or (pids_file.exists() and pids_file.read_text()), 90)
    if inner.poll() is not None:
        pytest.fail(f"the inner pytest ended early:\n{inner.communicate()[0]}")
    assert got, "the inner test never reported its fleet's processes"
    pids = [int(p) for p in pids_file.read_text().split()]
    assert len(pids) == 4 and all(alive(p) for p in pids), pids
    return pids


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_killing_the_test_process_leaves_no_fleet_process_behind(tmp_path: Path, sig: int) -> None:
    # SIGKILL and SIGTERM run no Python code: the orchestrator's parent-death signal
    # (canfleet/process.py) stops it, and it stops its nodes.
    inner = inner_pytest(tmp_path, HOLD)
    pids = held_pids(tmp_path, inner)
    inner.send_signal(sig)
    inner.communicate(timeout=30)
    assert inner.returncode == -sig
    assert wait_until(lambda: all_gone(pids), 60), [p for p in pids if alive(p)]


def test_ctrl_c_of_pytest_stops_the_fleet(tmp_path: Path) -> None:
    inner = inner_pytest(tmp_path, HOLD)
    pids = held_pids(tmp_path, inner)
    inner.send_signal(signal.SIGINT)
    out = inner.communicate(timeout=60)[0]
    assert inner.returncode == 2, out  # pytest: interrupted
    assert "KeyboardInterrupt" in out
    assert wait_until(lambda: all_gone(pids), 60), [p for p in pids if alive(p)]


def test_reports_carry_the_fleet_and_a_dead_node_fails_its_test(tmp_path: Path) -> None:
    junit = tmp_path / "junit.xml"
    inner = inner_pytest(tmp_path, REPORTS, f"--junitxml={junit}")
    out = inner.communicate(timeout=300)[0]
    assert inner.returncode == 1, out
    cases = {c.get("name"): c for c in ET.parse(junit).getroot().iter("testcase")}
    assert set(cases) == {"test_node_dies", "test_fails", "test_passes"}, out

    died = cases["test_node_dies"].find("failure")
    assert died is not None, out
    assert "NodeDiedError" in died.get("message", "") + (died.text or "")
    assert "io-21" in (died.text or "") and "signal 9" in (died.text or ""), died.text

    failed = cases["test_fails"]
    assert failed.find("failure") is not None
    props = {p.get("name"): p.get("value") for p in failed.iter("property")}
    log = Path(props["canfleet_log"])
    assert log.name == "orchestrator.log" and log.is_file()  # kept for the failed test
    assert "control API on" in log.read_text()
    capture = Path(props["canfleet_capture_1"])
    assert capture.suffix == ".pcap" and capture.is_file()
    assert cases["test_passes"].find("failure") is None and cases["test_passes"].find("error") is None

    # The terminal report's section: status, log path, captures.
    assert "Captured canfleet call" in out
    assert "topology python-pair" in out and "node quad-5 (quad-controller)" in out
    assert f"orchestrator log: {log}" in out
