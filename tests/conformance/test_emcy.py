"""EMCY (CiA 301 §7.2.7) decoded by python-canopen's EmcyConsumer (RemoteNode.emcy): frame
80h+node-ID, bytes 0-1 error code, byte 2 error register (1001h), bytes 3-7 manufacturer-specific;
the error also enters 1003h (§7.5.2.3) and clearing it sends 0000h (error reset)."""
from __future__ import annotations

from harness import observe_absence, wait_until

HB_NODE = 0x63  # a heartbeat producer that python-canopen plays, then lets fall silent


def wait_emcy(remote, code: int, start: int = 0):
    """The first EMCY with `code` in python-canopen's log after entry `start`. (EmcyConsumer.wait()
    only sees frames that arrive after it is called, so the log is polled instead.)"""
    return wait_until(lambda: next((e for e in remote.emcy.log[start:] if e.code == code), None))


def check_emcy(remote, emcy, code: int, register: int, data: bytes, history: int, what: str):
    assert emcy is not None, f"{what}: no EMCY {code:04X}h"
    assert (emcy.code, emcy.register, bytes(emcy.data)) == (code, register, data), \
        f"{what}: EMCY {emcy.code:04X}h reg {emcy.register:02X}h data {bytes(emcy.data).hex(' ')}"
    assert remote.sdo[0x1001].raw == register, f"{what}: 1001h"
    assert remote.sdo[0x1003][0].raw >= 1, f"{what}: 1003h sub 0"
    assert remote.sdo[0x1003][1].raw == history, f"{what}: 1003h sub 1 {remote.sdo[0x1003][1].raw:08X}h"
    assert emcy in remote.emcy.active


def test_device_faults_raise_and_reset_emcy(node, variant, fleet):
    """Each real fault of the variant (its manual's error table, or a CAN fault the fleet injects)
    raises its EMCY; repairing it sends the error reset (0000h, §7.2.7.1 state transition 5) with
    1001h back to 0."""
    remote = node.remote
    assert variant.device_faults, "no device fault defined for this variant"
    for fault in variant.device_faults:
        start = len(remote.emcy.log)
        fault.inject(fleet, node)
        emcy = wait_emcy(remote, fault.code, start)
        check_emcy(remote, emcy, fault.code, fault.register, fault.data, fault.history, fault.what)
        start = len(remote.emcy.log)
        fault.clear(fleet, node)
        reset = wait_emcy(remote, 0x0000, start)
        assert reset is not None, f"{fault.what}: no error reset EMCY after the repair"
        assert reset.register == 0 and remote.emcy.active == []
        assert remote.sdo[0x1001].raw == 0


def test_lost_heartbeat_raises_emcy_8130(node, variant):
    """§7.2.8.3.2.2 heartbeat consumer (1016h, §7.5.2.29): once node 63h's heartbeat was seen,
    its silence longer than the consumer time is a heartbeat event, EMCY 8130h (table 21)."""
    remote = node.remote
    network = node.network
    producer = network.send_periodic(0x700 + HB_NODE, b"\x05", 0.05)
    try:
        remote.sdo[0x1016][1].raw = (HB_NODE << 16) | 500
        # The consumer starts with the first heartbeat after the write (socketcand does not echo
        # our own frames, so they cannot be counted here).
        early = observe_absence(lambda: list(remote.emcy.log), 1.0,
                                "two consumer times (500 ms) with a heartbeat every 50 ms: a consumer that "
                                "missed them would have raised its event by then")
        assert early == [], "EMCY while the heartbeat was still produced"
    finally:
        producer.stop()
    emcy = wait_emcy(remote, 0x8130)
    check_emcy(remote, emcy, 0x8130, variant.hb_register, variant.hb_data(HB_NODE), variant.hb_history(HB_NODE),
               "lost heartbeat")
