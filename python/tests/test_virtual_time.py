"""Virtual time under the test's control (python/README.md "Virtual time"): the fleet stands still
while the test computes, runs exactly as far as the test waits, stamps what the test receives with
the simulated time it sees it at, judges expectations with the orchestrator's judges, and repeats a
scripted run byte for byte on an idle and on a loaded machine."""
from __future__ import annotations

import multiprocessing
import subprocess
import time
from pathlib import Path
from typing import Callable, List

import can
import canopen
import pytest

import canfleet
import canfleet._proto
from canfleet import BrokerRefusedError, ExpectationFailed, Fleet, OrchestratorError
from helpers import CONFORMANCE_IO_EDS, PAIR, quad_eds, wait_until

pytestmark = pytest.mark.topology("topologies/pair.textproto", time="virtual")

MakeBus = Callable[..., can.BusABC]
NS = 1e-9


def test_the_fleet_stands_still_while_the_test_computes(fleet: Fleet) -> None:
    before = fleet.now
    time.sleep(0.3)  # real time passes; simulated time does not
    assert fleet.now == before
    assert fleet.status().now_ns == fleet.clock.now_ns  # type: ignore[union-attr]


def test_run_moves_the_fleet_exactly_as_far_as_asked(fleet: Fleet) -> None:
    before_ns = fleet.clock.now_ns  # type: ignore[union-attr]
    fleet.run(0.123456789)
    assert fleet.clock.now_ns - before_ns == 123456789  # type: ignore[union-attr]
    assert fleet.status().now_ns == fleet.clock.now_ns  # type: ignore[union-attr]


def test_recv_timeout_counts_simulated_seconds(fleet: Fleet, canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus(can_filters=[{"can_id": 0x7FF, "can_mask": 0x7FF}])  # nobody sends 7FFh
    before = fleet.now
    assert bus.recv(0.75) is None
    assert abs(fleet.now - (before + 0.75)) < 2 * NS


def test_received_frames_are_stamped_at_the_simulated_time_the_test_sees_them(
        fleet: Fleet, canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus()
    stamps: List[float] = []
    for _ in range(20):
        msg = bus.recv(1.0)
        assert msg is not None
        assert abs(msg.timestamp - fleet.now) < 2 * NS, (msg, fleet.now)
        stamps.append(msg.timestamp)
    assert stamps == sorted(stamps)


def test_periodic_sends_keep_their_simulated_period(fleet: Fleet, canfleet_bus: MakeBus) -> None:
    sender = canfleet_bus(name="python-cyclic")
    watcher = canfleet_bus(can_filters=[{"can_id": 0x321, "can_mask": 0x7FF}])
    task = sender.send_periodic(can.Message(arbitration_id=0x321, data=b"\x01\x02", is_extended_id=False), 0.020)
    stamps = []
    while len(stamps) < 11:
        msg = watcher.recv(1.0)
        assert msg is not None
        stamps.append(msg.timestamp)
    task.stop()
    periods = [b - a for a, b in zip(stamps, stamps[1:])]
    # 20 ms on the bus's time line; arbitration may hold one frame back behind another (< 1 ms).
    assert all(abs(p - 0.020) < 0.001 for p in periods), periods


def test_an_expectation_is_judged_by_the_orchestrator_and_says_what_and_when(fleet: Fleet) -> None:
    fleet.run(0.2)  # the master knows a node's state from its heartbeat (100 ms)
    ok = fleet.expect("nmt", node="quad-5", state="operational")
    assert ok.passed and ok.decided == ok.opened
    with fleet.inject("heartbeat-loss", node="quad-5", receivers=["quad-6"]):
        start = fleet.now
        seen = fleet.expect("emcy", node="quad-6", code=0x8130, within=3.0)  # Quad manual §4.1
        # quad-6 consumes quad-5's heartbeat with a 500 ms timeout (pair.textproto)
        assert 0.4 < seen.decided - start < 0.7, seen
        assert fleet.now >= seen.decided
        assert "8130h" in seen.detail


def test_a_failed_expectation_raises_with_what_was_seen_at_the_end_of_its_window(fleet: Fleet) -> None:
    start = fleet.now
    with pytest.raises(ExpectationFailed) as failed:
        fleet.expect("emcy", node="quad-6", code=0x8130, within=0.5)
    assert failed.value.result.outcome == "FAIL"
    assert abs(failed.value.result.decided - (start + 0.5)) < 1e-6
    assert "8130h" in str(failed.value)


def test_a_bad_expectation_is_refused_with_the_loaders_message(fleet: Fleet) -> None:
    with pytest.raises(OrchestratorError, match="quad-9"):
        fleet.expect("nmt", node="quad-9", state="operational")
    with pytest.raises(OrchestratorError, match="after"):
        fleet.expect_text('after: "x" nmt { node: "quad-5" state: "operational" }')


def test_control_requests_happen_at_the_simulated_time_they_are_made(fleet: Fleet) -> None:
    fleet.run(0.5)
    at = fleet.now
    fleet.node("quad-5").io_set("IN1.voltage_mV", 2200)  # answered by the node: time runs to the answer
    assert fleet.now - at < 0.01
    assert fleet.node("quad-5").sdo_read(0x1017, 0, "u16") == 100  # Quad manual §3.1.1, producer 100 ms
    assert fleet.now - at < 0.02


def _spin() -> None:
    while True:
        pass


def _scripted_run(folder: Path, load: bool) -> bytes:
    """A test's actions (python-canopen SDO, NMT, faults with random drops) at exact simulated
    times; the capture of can0 is what must repeat."""
    hogs = [multiprocessing.Process(target=_spin, daemon=True) for _ in range(2 if load else 0)]
    for hog in hogs:
        hog.start()
    try:
        with Fleet.up(PAIR, time="virtual", seed=7, state_dir=folder) as fleet:
            capture = fleet.capture("can0", "can0.log", format="candump")  # in <folder>/captures
            net = canopen.Network()
            net.connect(interface="canfleet", channel="can0", fleet=fleet, name="python-canopen")
            io = canopen.RemoteNode(21, str(CONFORMANCE_IO_EDS))
            quad5 = canopen.RemoteNode(5, str(quad_eds()))
            net.add_node(io)
            net.add_node(quad5)
            io.sdo.download(0x2001, 0, b"segmented transfer of some length")
            assert io.sdo.upload(0x2001, 0).startswith(b"segmented")
            with fleet.inject("drop", node="quad-5", probability=0.3):
                fleet.run(1.0)
            quad5.nmt.state = "PRE-OPERATIONAL"
            assert quad5.nmt.wait_for_heartbeat(1.0) == "PRE-OPERATIONAL"
            fleet.run(0.5)
            capture.stop()
            net.disconnect()
            return capture.path.read_bytes()
    finally:
        for hog in hogs:
            hog.kill()


def test_a_scripted_run_repeats_byte_for_byte_on_an_idle_and_a_loaded_machine(tmp_path: Path) -> None:
    idle = _scripted_run(tmp_path / "idle", load=False)
    loaded = _scripted_run(tmp_path / "loaded", load=True)
    assert idle.count(b"\n") > 100
    assert idle == loaded


def test_the_clock_is_the_fleets_and_only_one_per_process(fleet: Fleet) -> None:
    assert canfleet.clock.active() is fleet.clock
    with Fleet.attach(fleet.control, broker=fleet.broker) as again:  # the same fleet: the same clock
        assert again.clock is fleet.clock
        assert again.now == fleet.now


def test_a_bus_on_a_virtual_fleet_nobody_drives_is_refused_with_the_reason(tmp_path: Path) -> None:
    # `canfleet up --time virtual` without --driven: its time runs on its own, as fast as it goes.
    ready = tmp_path / "ready"
    proc = subprocess.Popen([str(canfleet.fleet.find_binaries() / "canfleet"), "up", str(PAIR), "--time", "virtual",
                             "--ready-file", str(ready), "--control", "tcp://127.0.0.1:0", "--listen",
                             f"unix://{tmp_path / 'broker.sock'}", "--state-dir", str(tmp_path / "nodes"),
                             "--no-telemetry"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        assert wait_until(lambda: "state ready" in (ready.read_text() if ready.exists() else ""))
        values = dict(line.split(" ", 1) for line in ready.read_text().splitlines())
        with Fleet.attach(values["control"], broker=values["broker"]) as fleet:
            assert fleet.time == "virtual" and fleet.clock is None
            with pytest.raises(BrokerRefusedError, match="drives"):
                can.Bus(interface="canfleet", channel="can0", fleet=fleet)
            with pytest.raises(OrchestratorError, match="runs on its own"):
                fleet._call(canfleet._proto.control.Request(clock_advance=canfleet._proto.control.ClockAdvance(
                    until_ns=1)))
    finally:
        proc.terminate()
        proc.wait(timeout=60)
