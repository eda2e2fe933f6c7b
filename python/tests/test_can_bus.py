"""The python-can interface "canfleet" (canfleet.can_bus.CanfleetBus): a participant on a fleet
bus through the node wire protocol - arbitrated and acknowledged like a node, with error counters,
bus timestamps, faults and acceptance filters."""
from __future__ import annotations

import re
from typing import Callable, List

import can
import pytest

import canfleet
import canfleet.wire
from canfleet import Fleet
from canfleet.can_bus import CanfleetBus, acceptance_ids
from helpers import observe_absence, wait_until

pytestmark = pytest.mark.topology("topologies/pair.textproto")

MakeBus = Callable[..., can.BusABC]


def recv_matching(bus: can.BusABC, can_id: int, timeout: float = 5.0) -> can.Message:
    found = wait_until(lambda: (m := bus.recv(0.1)) is not None and m.arbitration_id == can_id and m, timeout)
    assert found, f"no {can_id:03X} frame"
    return found  # type: ignore[return-value]


def candump_frames(path) -> List[tuple]:
    """(seconds, id, data hex) of each line of a candump log."""
    out = []
    for line in path.read_text().splitlines():
        m = re.match(r"\((\d+\.\d+)\) \S+ ([0-9A-F]+)#(\S*)", line)
        if m:
            out.append((float(m.group(1)), int(m.group(2), 16), m.group(3).lower()))
    return out


def same_time(stamp: float, captured: List[float]) -> bool:
    """candump's log truncates to microseconds; a float of Unix seconds holds about 0.25 us."""
    return any(abs(stamp - t) < 1.5e-6 for t in captured)


def test_the_interface_is_registered_with_python_can(canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus("can0")
    assert isinstance(bus, CanfleetBus)
    assert bus.channel_info == "canfleet bus can0"
    assert bus.bus_bitrate == 250_000 and bus.paced
    assert bus.state is can.BusState.ACTIVE and (bus.tec, bus.rec) == (0, 0)


def test_received_frames_carry_the_bus_timestamps_of_the_capture(fleet: Fleet, canfleet_bus: MakeBus) -> None:
    capture = fleet.capture("can0", format="candump")
    bus = canfleet_bus("can0")
    got = [recv_matching(bus, 0x705) for _ in range(3)]
    assert wait_until(lambda: len([f for f in candump_frames(capture.path) if f[1] == 0x705]) >= 8)
    capture.stop()
    captured = [t for t, can_id, data in candump_frames(capture.path) if can_id == 0x705]
    for m in got:
        # The same frame, stamped with the end of frame on the bus (heartbeats are 100 ms apart).
        assert same_time(m.timestamp, captured), (m.timestamp, captured[:5])
        assert m.is_rx and m.channel == "can0" and bytes(m.data) == b"\x05"


def test_a_frame_sent_is_arbitrated_acknowledged_and_acted_on(fleet: Fleet, canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus("can0", receive_own_messages=True)
    capture = fleet.capture("can0", format="candump")
    assert wait_until(lambda: fleet.node("quad-5").status().nmt_state == "operational")
    bus.send(can.Message(arbitration_id=0x000, data=[0x02, 5], is_extended_id=False))  # NMT stop node 5
    own = wait_until(lambda: (m := bus.recv(0.1)) is not None and not m.is_rx and m)
    assert own and own.arbitration_id == 0x000  # TX confirmation: it was on the bus
    assert wait_until(lambda: fleet.node("quad-5").status().nmt_state == "stopped")
    assert wait_until(lambda: any(f[1] == 0 and f[2] == "0205" for f in candump_frames(capture.path)))
    assert same_time(own.timestamp, [t for t, i, d in candump_frames(capture.path) if i == 0])
    assert bus.tec == 0  # acknowledged by the nodes: no transmit error


def test_an_injected_bus_off_takes_the_participant_off_the_bus_until_it_recovers(
        fleet: Fleet, canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus("can0", name="py-tester")
    with fleet.inject("bus-off", node="py-tester", manual_recovery=True):
        assert bus.wait_for_state(can.BusState.ERROR, 10), bus.controller_state
        assert bus.controller_state == "bus-off" and bus.tec >= 256
        with pytest.raises(can.CanOperationError, match="bus-off"):
            bus.send(can.Message(arbitration_id=0x123, data=[1], is_extended_id=False))
    # Cleared: recovery (ISO 11898-1 §12.1.4.2), error-active again, and it sends.
    assert bus.wait_for_state(can.BusState.ACTIVE, 10), bus.controller_state
    bus.send(can.Message(arbitration_id=0x123, data=[1], is_extended_id=False))


def test_an_error_passive_fault_shows_in_the_counters(fleet: Fleet, canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus("can0", name="py-passive")
    fault = fleet.inject("error-passive", node="py-passive")
    assert bus.wait_for_state(can.BusState.PASSIVE, 10)
    assert bus.tec >= 128  # ISO 11898-1 §12.1.4.2: error-passive at TEC >= 128
    fault.clear()
    assert bus.wait_for_state(can.BusState.ACTIVE, 10)
    assert bus.tec == 127


def test_frame_faults_apply_to_what_the_participant_receives(fleet: Fleet, canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus("can0", name="py-deaf")
    recv_matching(bus, 0x705)
    with fleet.inject("rpdo-timeout", node="py-deaf", cob_id=0x705):
        while bus.recv(0) is not None:  # what arrived before the fault
            pass
        seen: List[can.Message] = []

        def heard() -> List[can.Message]:
            while (m := bus.recv(0)) is not None:
                if m.arbitration_id == 0x705:
                    seen.append(m)
            return seen

        # quad-5's heartbeat comes every 100 ms: 1 s is ten of them.
        assert not observe_absence(heard, 1.0, "ten periods of quad-5's 100 ms heartbeat"), seen
    recv_matching(bus, 0x705)


def test_python_can_filters_become_the_brokers_acceptance_filter(canfleet_bus: MakeBus) -> None:
    bus = canfleet_bus("can0", can_filters=[{"can_id": 0x705, "can_mask": 0x7FF, "extended": False}])
    # What reaches the interface at all (before python-can's own filtering): only 705h.
    raw = [bus._recv_internal(5.0)[0] for _ in range(5)]
    assert all(m is not None and m.arbitration_id == 0x705 for m in raw), raw
    bus.set_filters(None)  # every frame again
    assert wait_until(lambda: (m := bus.recv(0.1)) is not None and m.arbitration_id != 0x705)


def test_acceptance_ids_follow_python_cans_matching_rules() -> None:
    assert acceptance_ids(None) is None
    assert acceptance_ids([{"can_id": 0, "can_mask": 0}]) is None
    assert acceptance_ids([{"can_id": 0x700, "can_mask": 0x780}]) == list(range(0x700, 0x780))
    assert acceptance_ids([{"can_id": 0x18FF0000, "can_mask": 0x1FFFFFFF, "extended": True}]) == []
    assert acceptance_ids([{"can_id": 0x185, "can_mask": 0x7FF}, {"can_id": 0x705, "can_mask": 0x7FF}]) == [0x185, 0x705]


def test_a_wire_version_mismatch_is_a_clear_error(fleet: Fleet, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(canfleet.wire, "PROTOCOL_VERSION", canfleet.WIRE_PROTOCOL_VERSION + 1)
    with pytest.raises(canfleet.WireVersionError) as e:
        can.Bus(interface="canfleet", channel="can0", fleet=fleet)
    assert e.value.ours == canfleet.WIRE_PROTOCOL_VERSION + 1
    assert e.value.theirs == canfleet.WIRE_PROTOCOL_VERSION
    assert f"version {canfleet.WIRE_PROTOCOL_VERSION + 1}" in str(e.value)
    assert "pip install ./python" in str(e.value)


def test_an_unknown_bus_is_refused_with_the_brokers_reason(fleet: Fleet) -> None:
    with pytest.raises(canfleet.BrokerRefusedError, match="unknown bus can9"):
        can.Bus(interface="canfleet", channel="can9", fleet=fleet)


def test_the_bus_finds_the_running_fleet_and_ends_with_it(fleet: Fleet) -> None:
    bus = can.Bus(interface="canfleet", channel="can0")  # canfleet.current(): this test's fleet
    try:
        recv_matching(bus, 0x705)
        fleet.close()
        with pytest.raises(can.CanOperationError):
            wait_until(lambda: bus.recv(0.1) and False, 30)
    finally:
        bus.shutdown()
