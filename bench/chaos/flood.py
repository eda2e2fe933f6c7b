"""The floods of issue 32, measured: what the orchestrator's memory and descriptors do, and what
the control API's latency is, while clients abuse every endpoint at once. Prints figures; not a
test (tests/system/chaos and the bounds' own tests are).

  .venv/bin/python bench/chaos/flood.py [--seconds S]

The floods (each as the issue found them, before the bounds): 8 broker clients that never read
(on a bus made busy by a babbling idiot), 200 control connections each with a 1 MiB message begun
and half sent, 200 control connections that say nothing, 20 socketcand clients that ask for every
frame and never read.
"""
from __future__ import annotations

import argparse
import os
import socket
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import List, Tuple

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "python"))
sys.path.insert(0, str(REPO / "tests" / "system" / "chaos"))

from canfleet import Fleet  # noqa: E402
from canfleet import wire  # noqa: E402
from canfleet._proto import control as pb  # noqa: E402
from canfleet._proto import wire as wpb  # noqa: E402
from canfleet.control import ControlClient  # noqa: E402
from chaos import TOPOLOGY, proc_figures  # noqa: E402


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def connect(endpoint: str) -> socket.socket:
    if endpoint.startswith("unix://"):
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.connect(endpoint[len("unix://"):])
    else:
        host, port = endpoint[len("tcp://"):].rsplit(":", 1)
        s = socket.create_connection((host, int(port)))
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    return s


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=45.0, help="how long to watch after the floods start")
    args = p.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="canfleet-flood-"))
    topology = folder / "flood.textproto"
    socketcand = free_port()
    topology.write_text(TOPOLOGY.read_text()
                        .replace('"../../../topologies/eds/', f'"{REPO}/topologies/eds/')
                        .replace('bus { name: "can0" ', f'bus {{ name: "can0" socketcand_port: {socketcand} ', 1))
    with Fleet.up(topology, state_dir=folder / "state") as fleet:
        assert fleet.pid is not None and fleet.broker is not None
        time.sleep(3)
        rss0, fds0 = proc_figures(fleet.pid)
        latencies: List[float] = []
        flooding = threading.Event()
        stop = threading.Event()

        def probe() -> None:
            with ControlClient(fleet.control, timeout=10) as client:
                while not stop.wait(0.05):
                    t = time.monotonic()
                    client.call(pb.Request(status=pb.StatusRequest()))
                    if flooding.is_set():
                        latencies.append((time.monotonic() - t) * 1000)

        prober = threading.Thread(target=probe, daemon=True)
        prober.start()
        fleet.inject("babbling-idiot", node="quad-5", duration_ms=int(args.seconds * 1000))
        held: List[socket.socket] = []
        flooding.set()
        for i in range(8):  # broker clients that never read
            s = connect(fleet.broker)
            s.sendall(wire.envelope(hello=wpb.Hello(protocol_version=wire.PROTOCOL_VERSION, bus="can0",
                                                    node_name=f"flood-{i}", role=wpb.ROLE_MONITOR)))
            held.append(s)
        port = int(fleet.control.rsplit(":", 1)[1])
        refused = 0
        for _ in range(200):  # 1 MiB messages begun and half sent
            s = connect(fleet.control)
            try:
                s.sendall(b"\x80\x80\x40" + b"x" * (512 * 1024))  # varint 1 MiB, then half of it
            except OSError:
                refused += 1
            held.append(s)
        for _ in range(200):  # silent
            try:
                held.append(socket.create_connection(("127.0.0.1", port), timeout=5))
            except OSError:
                refused += 1
        for _ in range(20):  # socketcand clients that never read
            s = socket.create_connection(("127.0.0.1", socketcand), timeout=5)
            s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            s.sendall(b"< open can0 >< rawmode >")
            held.append(s)
        samples: List[Tuple[float, int, int]] = []
        t0 = time.monotonic()
        while time.monotonic() - t0 < args.seconds:
            rss, fds = proc_figures(fleet.pid)
            samples.append((time.monotonic() - t0, rss, fds))
            time.sleep(0.5)
        flooding.clear()
        for s in held:
            s.close()
        time.sleep(2)
        rss1, fds1 = proc_figures(fleet.pid)
        stop.set()
        prober.join(timeout=10)
        fleet.nmt("start")  # the babbling idiot's victims went pre-operational, as they should
        time.sleep(3)
        status = fleet.status()
        peak_rss = max(r for _, r, _ in samples)
        peak_fds = max(f for _, _, f in samples)
        ordered = sorted(latencies)
        print(f"flood: {len(held)} hostile connections ({refused} refused at connect), babbling idiot on can0, "
              f"{args.seconds:g} s")
        print(f"flood: orchestrator RSS {rss0 / 1024:.1f} MiB before, peak {peak_rss / 1024:.1f} MiB, "
              f"{rss1 / 1024:.1f} MiB after; descriptors {fds0} before, peak {peak_fds}, {fds1} after")
        print("flood: RSS over time (s: MiB): " + ", ".join(f"{t:.0f}: {r / 1024:.0f}" for t, r, _ in samples[::10]))
        if ordered:
            print(f"flood: control API latency under the flood (status, ms): p50 "
                  f"{ordered[len(ordered) // 2]:.1f} p99 {ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]:.1f} "
                  f"max {ordered[-1]:.1f} over {len(ordered)} requests")
        print(f"flood: nodes operational after: {sum(1 for n in status.nodes if n.nmt_state == 'operational')}"
              f"/{len(status.nodes)}")
    os.system(f"rm -rf {folder}")


if __name__ == "__main__":
    main()
