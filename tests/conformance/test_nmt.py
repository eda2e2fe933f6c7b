"""NMT (CiA 301 §7.2.8.3.1, §7.3.2) driven by python-canopen's NmtMaster, observed through the
heartbeat (§7.2.8.3.2.2) the node produces once python-canopen writes 1017h."""
from __future__ import annotations

import pytest
from canopen.sdo import SdoCommunicationError

from harness import observe_absence, wait_until

STATE_BYTE = {"OPERATIONAL": 0x05, "STOPPED": 0x04, "PRE-OPERATIONAL": 0x7F}


def heartbeat_state(node, since: int):
    """The state byte of the latest heartbeat after frame mark `since`, or None."""
    frames = [m for m in node.frames.since(since, 0x700 + node.node_id) if len(m.data) == 1]
    return frames[-1].data[0] if frames else None


def wait_heartbeat_state(node, state: str) -> bool:
    """A heartbeat in `state` (two in a row, so not one sent before the command), as python-canopen's
    wait_for_heartbeat() decodes it."""
    mark = node.frames.mark()

    def seen():
        frames = [m.data[0] for m in node.frames.since(mark, 0x700 + node.node_id) if len(m.data) == 1]
        return len(frames) >= 2 and frames[-1] == frames[-2] == STATE_BYTE[state]

    if not wait_until(seen):
        return False
    return node.remote.nmt.wait_for_heartbeat(timeout=10) == state


def test_heartbeat_follows_nmt_commands(node, variant):
    """§7.3.2.2: after boot-up the node is pre-operational; commands 01h/02h/80h move it to
    operational, stopped, pre-operational; each heartbeat carries the state (05h, 04h, 7Fh) in one
    byte with bit 7 clear (the toggle bit is for node guarding only)."""
    remote = node.remote
    start = node.frames.mark()
    remote.sdo[0x1017].raw = 50  # ms; python-canopen's first SDO write
    assert wait_heartbeat_state(node, "PRE-OPERATIONAL")
    for state in ("OPERATIONAL", "STOPPED", "PRE-OPERATIONAL", "OPERATIONAL", "PRE-OPERATIONAL"):
        remote.nmt.state = state
        assert wait_heartbeat_state(node, state), f"no heartbeat in {state} after the NMT command"
    beats = node.frames.since(start, 0x700 + node.node_id)
    assert len(beats) >= 10
    assert all(m.dlc == 1 and not m.is_remote_frame and m.data[0] & 0x80 == 0 for m in beats)


def test_heartbeat_period_zero_stops_the_producer(node, variant):
    """§7.5.2.30: 1017h = 0 disables the heartbeat. The SDO confirmation comes after the node
    applied the value, so no heartbeat may follow it (frames keep their order on the bus)."""
    remote = node.remote
    remote.sdo[0x1017].raw = 50
    assert wait_heartbeat_state(node, "PRE-OPERATIONAL")
    remote.sdo[0x1017].raw = 0
    mark = node.frames.mark()
    late = observe_absence(lambda: node.frames.since(mark, 0x700 + node.node_id), 1.0,
                           "20 periods of the former 50 ms heartbeat")
    assert late == []


def test_stopped_node_serves_no_sdo(node, variant):
    """§7.3.2.2.4 table 48: in stopped only NMT and error control are active, so an SDO request gets
    no answer; back in pre-operational SDO works again."""
    remote = node.remote
    remote.sdo[0x1017].raw = 50
    remote.nmt.state = "STOPPED"
    assert wait_heartbeat_state(node, "STOPPED")
    remote.sdo.RESPONSE_TIMEOUT = 1.0
    with pytest.raises(SdoCommunicationError):
        remote.sdo.upload(0x1000, 0)
    remote.sdo.RESPONSE_TIMEOUT = 5.0
    remote.nmt.state = "PRE-OPERATIONAL"
    assert wait_heartbeat_state(node, "PRE-OPERATIONAL")
    assert remote.sdo[0x1017].raw == 50


@pytest.mark.parametrize("command", ["RESET COMMUNICATION", "RESET"])
def test_resets_boot_up_again_with_defaults(node, variant, command):
    """§7.3.2.1: reset communication (82h) and reset node (81h) end in a new boot-up (700h+ID,
    00h) and pre-operational; the communication parameters (1000h-1FFFh, 1017h here) are back at
    their defaults (nothing was stored with 1010h)."""
    remote = node.remote
    remote.sdo[0x1017].raw = 50
    remote.nmt.state = "OPERATIONAL"
    assert wait_heartbeat_state(node, "OPERATIONAL")
    mark = node.frames.mark()
    remote.nmt.state = command
    assert node.wait_bootup(mark, node.node_id), f"no boot-up after {command}"
    default = remote.object_dictionary[0x1017].default or 0
    assert remote.sdo[0x1017].raw == default
    # Pre-operational: SDO answers, and a heartbeat switched on shows 7Fh.
    remote.sdo[0x1017].raw = 50
    assert wait_heartbeat_state(node, "PRE-OPERATIONAL")
