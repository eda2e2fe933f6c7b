"""A few minutes of chaos against a real fleet (chaos.py; issue 32): kills of nodes and of the
orchestrator, stores interrupted by kill -9, power cycles, a babbling idiot, hostile clients on
every port. The fleet must come back each time, stored parameters must be one save's, no process
may be left behind, and the orchestrator's memory and descriptors must stay bounded. The hour-long
run is a benchmark: bench/chaos/run.sh."""
from __future__ import annotations

import os
from pathlib import Path

from chaos import Chaos

DURATION_S = float(os.environ.get("CANFLEET_CHAOS_S", "150"))


def test_the_fleet_survives_chaos(tmp_path: Path) -> None:
    report = Chaos(tmp_path, seed=int(os.environ.get("CANFLEET_CHAOS_SEED", "1"))).run(DURATION_S)
    for line in report.lines():
        print("chaos: " + line)
    assert report.events.get("orchestrator killed (kill -9)", 0) >= 1
    assert report.stores >= 1 and report.values_checked >= 3
    assert report.leftover_processes == 0
    assert report.control_failures == 0, "the control API failed a request while the orchestrator ran"
    for o in report.orchestrator:
        # Bounded: what hostile clients and floods leave behind is gone once they are (slack for
        # the allocator's and DDS's own growth).
        assert o["fds_end"] <= o["fds_start"] + 16, o
        assert o["rss_end"] <= o["rss_start"] + 64 * 1024, o
