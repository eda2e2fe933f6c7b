"""LSS (CiA 305) with python-canopen's LssMaster, for the variants whose EDS says LSS_Supported=1
(CiA 306 §4.5.2 [DeviceInfo])."""
from __future__ import annotations


import pytest
from canopen.lss import LssMaster

import eds_view
from harness import BOOT_TIMEOUT, tail, wait_until


SERIAL = 4242
NEW_ID = 0x30


def lss_supported(variant) -> bool:
    import canopen
    return bool(canopen.import_od(str(variant.eds)).device_information.LSS_supported)


def attached(node) -> bool:
    """The orchestrator's view (its status): the external node has a broker connection.
    A refused connection (see the node's log) fails at once instead of waiting."""
    if "refused" in node.log.read_text(errors="replace"):
        raise AssertionError(f"the broker refused the node:\n{tail(node.log, 3)}")
    return node.fleet.attached(node.variant.name)


@pytest.fixture
def lss_node(start_node, variant):
    if not lss_supported(variant):
        pytest.skip(f"{variant.eds.name}: LSS_Supported=0")
    return start_node(["--serial", str(SERIAL)])


def test_switch_selective_change_node_id_and_store(lss_node, variant):
    """§8.3.2 switch state selective with the LSS address (1018h sub 1-4) → 44h; §8.3.3 inquire
    node-ID (5Eh) returns the active one; §8.3.3 configure node-ID (11h) and store configuration
    (17h) answer error code 0; switching back to waiting and an NMT reset communication bring the
    node up with the new ID (boot-up 700h+new ID); a power cycle (the process started again with
    its old --node-id and the same state folder) keeps the stored ID."""
    node = lss_node
    remote = node.remote
    address = [remote.sdo[0x1018][sub].raw for sub in (1, 2, 3, 4)]
    assert address[3] == SERIAL
    lss = node.network.lss
    assert lss.send_switch_state_selective(*address), "no 44h answer to switch state selective"
    assert lss.inquire_node_id() == variant.node_id
    lss.configure_node_id(NEW_ID)
    lss.store_configuration()
    mark = node.frames.mark()
    lss.send_switch_state_global(LssMaster.WAITING_STATE)
    node.network.nmt.send_command(0x82)  # reset communication, all nodes (CiA 301 §7.2.8.3.1)
    assert node.wait_bootup(mark, NEW_ID), "no boot-up with the new node-ID"
    moved = node.add_remote(NEW_ID)
    assert moved.sdo[0x1018][4].raw == SERIAL
    # After reset communication every communication object is at its default again, and the
    # $NODEID defaults (CiA 306 §4.6.3.2; the pre-defined connection set, CiA 301 §7.3.5) use
    # the new node-ID.
    relative = [v for v in eds_view.variables(moved.object_dictionary) if getattr(v, "relative", False)]
    assert relative, "no $NODEID default in the EDS"
    for var in relative:
        assert moved.sdo.upload(var.index, var.subindex) == eds_view.default_bytes(var), eds_view.label(var)

    # Power cycle: stored configuration wins over the command line's node-ID (§8.3.3 store).
    assert node.stop_process() == 0
    mark = node.frames.mark()
    node.start(expect_node_id=NEW_ID)
    assert node.wait_bootup(mark, NEW_ID)
    assert lss.send_switch_state_selective(*address)
    assert lss.inquire_node_id() == NEW_ID
    lss.send_switch_state_global(LssMaster.WAITING_STATE)


def test_fast_scan_finds_an_unconfigured_node(start_node, variant):
    """§8.3.5 LSS fastscan: python-canopen's fast_scan() finds the 128-bit LSS address of a node
    without node-ID (canfleet-node --node-id 255 sends no boot-up, CiA 305 §5.2) and leaves it in
    configuration state; configure node-ID and switching to waiting then bring it up (§8.3.3)."""
    if not lss_supported(variant):
        pytest.skip(f"{variant.eds.name}: LSS_Supported=0")
    # Few one bits in the serial: python-canopen's fast scan waits out a timeout per one bit.
    node = start_node(["--serial", "1"], start_process=False)
    node.start(cli_node_id=255, wait=False)
    # No boot-up to wait for: wait until the orchestrator reports the node attached to the bus.
    assert wait_until(lambda: attached(node), BOOT_TIMEOUT), \
        f"canfleet-node --node-id 255 never attached to the bus:\n{tail(node.log, 5)}"
    lss = node.network.lss
    lss.RESPONSE_TIMEOUT = 1.0  # python-canopen waits out one timeout per one bit of the address
    lss.send_switch_state_global(LssMaster.WAITING_STATE)
    found, address = lss.fast_scan()
    assert found, "fast scan found no unconfigured node"
    od = node.remote.object_dictionary
    assert address[0] == od[0x1018][1].default and address[1] == od[0x1018][2].default
    assert address[3] == 1
    lss.RESPONSE_TIMEOUT = 5.0
    lss.configure_node_id(variant.node_id)
    mark = node.frames.mark()
    lss.send_switch_state_global(LssMaster.WAITING_STATE)
    assert node.wait_bootup(mark, variant.node_id)
    node.node_id = variant.node_id
    assert node.remote.sdo[0x1018][4].raw == 1
