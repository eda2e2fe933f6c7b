"""A heartbeat loss seen by python-canopen's heartbeat consumer, in virtual time.

quad-5 sends its heartbeat every 100 ms. The test cuts it off from this master only (a
`heartbeat-loss` fault for receiver "python-canopen"): python-canopen's wait_for_heartbeat then
times out after its 1 s (simulated), while quad-6, which still hears quad-5, reports nothing.
After the fault is cleared the next heartbeat comes within one period.

    python python/examples/heartbeat_loss.py
"""
from __future__ import annotations

import canopen

from _common import PAIR, Stopwatch, quad_eds
from canfleet import Fleet


def main() -> None:
    watch = Stopwatch()
    with Fleet.up(PAIR, time="virtual") as fleet:
        network = canopen.Network()
        network.connect(interface="canfleet", channel="can0", fleet=fleet, name="python-canopen")
        quad5 = canopen.RemoteNode(5, str(quad_eds()))
        network.add_node(quad5)
        assert quad5.nmt.wait_for_heartbeat(timeout=1.0) == "OPERATIONAL"  # CiA 301 §7.2.8.3.2.2
        with fleet.inject("heartbeat-loss", node="quad-5", receivers=["python-canopen"]):
            lost_at = fleet.now
            try:
                quad5.nmt.wait_for_heartbeat(timeout=1.0)
                raise SystemExit("FAIL: a heartbeat reached python-canopen through the fault")
            except canopen.nmt.NmtError as e:
                print(f"t={fleet.now:.3f} s: python-canopen: {e} (waited {fleet.now - lost_at:.3f} s)")
            # quad-6 still hears quad-5: no heartbeat-loss EMCY (8130h, Quad manual §4.1) from it
            fleet.expect("no_emcy", node="quad-6", code=0x8130, within=0.5)
        back = quad5.nmt.wait_for_heartbeat(timeout=1.0)
        print(f"t={fleet.now:.3f} s: heartbeat back, quad-5 {back}")
        assert back == "OPERATIONAL"
        network.disconnect()
        watch.report(fleet, "heartbeat_loss: ok")


if __name__ == "__main__":
    main()
