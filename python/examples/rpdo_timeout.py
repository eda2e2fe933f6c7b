"""An RPDO timeout provoked by the test's own master, in virtual time.

python-canopen sends quad-6's RPDO1 (185h) every 100 ms (Network.send_periodic: on a driven fleet
a task on the simulated clock), quad-6 drives its output from it, then the master stops sending:
500 ms later (1400h sub 5, the RPDO's deadline) quad-6 reports EMCY 8250h (CiA 301 §7.2.7.1, RPDO
timeout) and goes pre-operational (Quad manual §4.1), which python-canopen's EMCY consumer and
heartbeat consumer both see, at the simulated times they happened.

    python python/examples/rpdo_timeout.py
"""
from __future__ import annotations

import struct

import canopen

from _common import HERE, Stopwatch, quad_eds
from canfleet import Fleet


def main() -> None:
    watch = Stopwatch()
    with Fleet.up(HERE / "rpdo-master.textproto", time="virtual") as fleet:
        network = canopen.Network()
        network.connect(interface="canfleet", channel="can0", fleet=fleet, name="python-canopen")
        quad6 = canopen.RemoteNode(6, str(quad_eds()))
        network.add_node(quad6)
        assert quad6.nmt.wait_for_heartbeat(timeout=1.0) == "OPERATIONAL"
        ain = struct.pack("<4H", 1500, 1500, 1500, 1500)  # quad-5's TPDO1 would carry AIN1..4 (mV)
        task = network.send_periodic(0x185, ain, 0.100)
        fleet.expect("io", node="quad-6", name="OUT1.current_mA", value="1500", within=2.0)
        stopped_at = fleet.now
        task.stop()  # the master stops sending
        seen = fleet.expect("emcy", node="quad-6", code=0x8250, within=2.0)
        print(f"t={seen.decided:.3f} s: {seen.detail} ({seen.decided - stopped_at:.3f} s after the last "
              "RPDO was due)")
        # python-canopen's EMCY consumer has it already: the expectation returned when it was on the bus.
        emcy = next((e for e in quad6.emcy.log if e.code == 0x8250), None) or quad6.emcy.wait(0x8250, timeout=1.0)
        assert emcy is not None, "python-canopen's EMCY consumer saw no 8250h"
        print(f"python-canopen: {emcy}")
        state = quad6.nmt.wait_for_heartbeat(timeout=1.0)
        print(f"t={fleet.now:.3f} s: quad-6 is {state}")
        assert state == "PRE-OPERATIONAL"
        network.disconnect()
        watch.report(fleet, "rpdo_timeout: ok")


if __name__ == "__main__":
    main()
