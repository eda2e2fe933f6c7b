"""A ten-minute soak in virtual time: 30 % of quad-5's frames are dropped at random (a seeded
`drop` fault), and every heartbeat-loss EMCY quad-6 reports (8130h, Quad manual §4.1; consumer
timeout 500 ms in pair.textproto) must be a real loss: no heartbeat of quad-5 reached the bus in
the 500 ms before it. The other way round too: every gap longer than the timeout is reported.

python-can's filters keep this master to the frames it checks (quad-5's heartbeat, quad-6's EMCY),
so the fleet stops for Python only when one of those arrives.

    python python/examples/soak.py [SIMULATED_SECONDS]
"""
from __future__ import annotations

import sys
import threading
from typing import List

import can
import canopen

from _common import PAIR, Stopwatch, quad_eds
from canfleet import Fleet

TIMEOUT = 0.5  # quad-6's consumer time for quad-5 (1016h, pair.textproto)
SLACK = 0.0015  # from the consumer's timer to the end of its EMCY frame on the bus, at most


class Heartbeats(can.Listener):
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.times: List[float] = []

    def on_message_received(self, msg: can.Message) -> None:
        if msg.arbitration_id == 0x705:
            with self.lock:
                self.times.append(msg.timestamp)


def main(seconds: float) -> None:
    watch = Stopwatch()
    with Fleet.up(PAIR, time="virtual", seed=2026) as fleet:
        network = canopen.Network()
        network.connect(interface="canfleet", channel="can0", fleet=fleet, name="python-canopen",
                        can_filters=[{"can_id": 0x705, "can_mask": 0x7FF}, {"can_id": 0x086, "can_mask": 0x7FF}])
        heartbeats = Heartbeats()
        network.notifier.add_listener(heartbeats)
        quad6 = canopen.RemoteNode(6, str(quad_eds()))
        network.add_node(quad6)
        fleet.run(1.0)
        start = fleet.now
        with fleet.inject("drop", node="quad-5", probability=0.3):
            fleet.run(seconds)
        end = fleet.now
        fleet.run(1.0)
        losses = [e.timestamp for e in quad6.emcy.log if e.code == 0x8130 and start <= e.timestamp <= end]
        beats = [t for t in heartbeats.times if start - 1.0 <= t <= end]
        # An EMCY ends SLACK after its consumer's timer fired (its own frame, 0.5 ms at 250 kbit/s,
        # and a frame ahead of it), and the timer fired TIMEOUT after the last heartbeat: a heartbeat
        # inside (timer - TIMEOUT, timer) makes the report false; the timer is at most SLACK before the
        # EMCY ended, so a heartbeat in (t - TIMEOUT, t - SLACK) certainly does. A heartbeat ending at the very
        # instant the timer fires counts as late (timers before frames at one instant: the broker's
        # tie rule, orchestrator/broker/README.md "Ties"), so a gap of exactly TIMEOUT is a loss.
        false_reports = [t for t in losses if any(t - TIMEOUT < b < t - SLACK for b in beats)]
        gaps = [(a, b) for a, b in zip(beats, beats[1:]) if b - a >= TIMEOUT - 1e-9 and a + TIMEOUT < end]
        missed = [(a, b) for a, b in gaps if not any(a + TIMEOUT <= t <= a + TIMEOUT + SLACK for t in losses)]
        print(f"{len(beats)} heartbeats of quad-5 reached the bus, {len(gaps)} gaps over {TIMEOUT * 1000:.0f} ms, "
              f"{len(losses)} heartbeat-loss EMCYs from quad-6")
        network.disconnect()
        watch.report(fleet, "soak")
        if false_reports or missed:
            raise SystemExit(f"FAIL: losses reported with a heartbeat in the window: {false_reports[:5]}; "
                             f"gaps not reported: {missed[:5]}")
        if not gaps:
            raise SystemExit("FAIL: no gap long enough in the soak: the check proved nothing")
        print("soak: ok (no heartbeat loss reported falsely, none missed)")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 600.0)
