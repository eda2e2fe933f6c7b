"""python-canopen, unchanged, on the "canfleet" python-can interface: SDO (expedited, segmented,
block), NMT, heartbeat, TPDO callbacks and EMCY against the fleet's nodes (real processes)."""
from __future__ import annotations

import threading
from typing import Generator, List

import canopen
import pytest

from canfleet import Fleet
from helpers import CONFORMANCE_IO_EDS, quad_eds, wait_until

pytestmark = pytest.mark.topology("topologies/pair.textproto")

SDO_TIMEOUT = 5.0  # a bound, not an expectation


@pytest.fixture
def network(fleet: Fleet) -> Generator[canopen.Network, None, None]:
    net = canopen.Network()
    net.connect(interface="canfleet", channel="can0", fleet=fleet, name="python-canopen")
    yield net
    net.disconnect()


def remote(network: canopen.Network, node_id: int, eds: object) -> canopen.RemoteNode:
    node = canopen.RemoteNode(node_id, str(eds))
    node.sdo.RESPONSE_TIMEOUT = SDO_TIMEOUT
    network.add_node(node)
    return node


def test_sdo_expedited_write_and_read(network: canopen.Network) -> None:
    io = remote(network, 21, CONFORMANCE_IO_EDS)
    io.sdo[0x1017].raw = 700  # CiA 301 §7.2.4.3.3 expedited download, §7.2.4.3.6 upload
    assert io.sdo[0x1017].raw == 700
    with pytest.raises(canopen.SdoAbortedError) as e:
        io.sdo.upload(0x5FFF, 0)
    assert e.value.code == 0x06020000


def test_sdo_segmented_download_and_upload(network: canopen.Network) -> None:
    io = remote(network, 21, CONFORMANCE_IO_EDS)
    text = "canfleet over python-can: segmented"  # > 4 bytes: CiA 301 §7.2.4.3.7-§7.2.4.3.12
    io.sdo.download(0x2001, 0, text.encode(), force_segment=True)
    assert io.sdo.upload(0x2001, 0) == text.encode()


def test_sdo_block_download_and_upload(network: canopen.Network) -> None:
    io = remote(network, 21, CONFORMANCE_IO_EDS)
    data = bytes(range(256)) * 4  # 1024 bytes: more than one block of 127 segments (§7.2.4.3.14)
    with io.sdo.open(0x2000, 0, "wb", size=len(data), block_transfer=True) as f:
        f.write(data)
    with io.sdo.open(0x2000, 0, "rb", block_transfer=True) as f:
        assert f.read() == data


def test_nmt_commands_and_the_heartbeat_state(network: canopen.Network) -> None:
    quad5 = remote(network, 5, quad_eds())
    assert quad5.nmt.wait_for_heartbeat(timeout=5) == "OPERATIONAL"  # CiA 301 §7.2.8.3.2.2
    quad5.nmt.state = "PRE-OPERATIONAL"
    assert wait_until(lambda: quad5.nmt.wait_for_heartbeat(timeout=5) == "PRE-OPERATIONAL")
    quad5.nmt.state = "OPERATIONAL"
    assert wait_until(lambda: quad5.nmt.wait_for_heartbeat(timeout=5) == "OPERATIONAL")


def test_heartbeat_consumer_sees_a_lost_heartbeat(fleet: Fleet, network: canopen.Network) -> None:
    quad5 = remote(network, 5, quad_eds())
    assert quad5.nmt.wait_for_heartbeat(timeout=5) == "OPERATIONAL"
    with fleet.inject("heartbeat-loss", node="quad-5", receivers=["python-canopen"]):
        # python-canopen's consumer: no heartbeat within its wait while the others still get it.
        with pytest.raises(canopen.nmt.NmtError):
            quad5.nmt.wait_for_heartbeat(timeout=1.0)  # ten 100 ms periods
        assert fleet.node("quad-6").status().last_emcy.code != 0x8130  # quad-6 still hears quad-5
    assert quad5.nmt.wait_for_heartbeat(timeout=5) == "OPERATIONAL"


def test_tpdo_callback_gets_the_mapped_input(fleet: Fleet, network: canopen.Network) -> None:
    quad5 = remote(network, 5, quad_eds())
    quad5.tpdo.read()  # mapping read by SDO (CiA 301 §7.5.2.35-§7.5.2.36)
    received: List[int] = []
    lock = threading.Lock()

    def on_tpdo(pdo_map: canopen.pdo.PdoMap) -> None:
        with lock:
            received.append(int(pdo_map[0].raw))

    quad5.tpdo[1].add_callback(on_tpdo)
    fleet.node("quad-5").io_set("IN1.voltage_mV", 2100)
    # TPDO1 185h maps AIN1 (7100h.1, mV; Quad manual §3.1.1).
    assert wait_until(lambda: 2100 in received), received[-5:]


def test_emcy_of_a_lost_heartbeat(fleet: Fleet, network: canopen.Network) -> None:
    quad6 = remote(network, 6, quad_eds())
    # quad-6 monitors quad-5 from its first heartbeat (CiA 301 §7.2.8.3.2.2), which the
    # orchestrator sees too.
    assert wait_until(lambda: fleet.node("quad-5").status().nmt_state == "operational")
    with fleet.inject("heartbeat-loss", node="quad-5", receivers=["quad-6"]):
        emcy = quad6.emcy.wait(0x8130, timeout=10)  # Quad manual §4.1, CiA 301 §7.2.7
        assert emcy is not None
        assert emcy.register & 0x01
        assert emcy.data[:2] == bytes([0x05, 0x08])  # channel: node 5; description 08h lost heartbeat
    reset = wait_until(lambda: any(e.code == 0x0000 for e in quad6.emcy.log))  # error reset (§7.2.7.1)
    assert reset, quad6.emcy.log
