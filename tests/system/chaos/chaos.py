"""Chaos against a real fleet (issue 32, "an hour of chaos, survived"): the five products with their
heartbeat consumers and RPDO deadlines (chaos.textproto), in real time, while random things go
wrong in turn: a node process killed (kill -9), a store of parameters (1010h "save all") with the
node killed while it stores, a power cycle, a babbling idiot at full load, silent and slow clients
and garbage on every port, the orchestrator itself killed (kill -9) and started again on the same
state. Throughout, a second connection measures the control API's latency; after each event every
node must be back, configured and operational, and the stored parameters of the node killed
while storing must be one save's, old or new, never a mix.

Real time because processes die and come back (a kill is no simulated event) and because slow
clients and floods are about real sockets. Used by test_chaos.py (a few minutes, in the suite) and
bench/chaos/run.sh (an hour, prints the figures).
"""
from __future__ import annotations

import os
import random
import signal
import socket
import statistics
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Optional, Tuple

from canfleet import Fleet
from canfleet.control import ControlClient
from canfleet.errors import CanfleetError
from canfleet._proto import control as pb

HERE = Path(__file__).resolve().parent
TOPOLOGY = HERE / "chaos.textproto"

# The node whose stores are interrupted, and one object of each 1010h group it stores
# (quad-controller.od: 1801h.5 TPDO2 event timer, 2001h.1 low threshold AIN1, 6132h.1 decimal
# digits AIN1, 0..9). A save's generation g is written as 1801h.5 = 1000 + g % 1000,
# 2001h.1 = 1000 + g % 2000 (below the 3500 mV high threshold), 6132h.1 = g % 10: values read back
# after a restart must be one save's triple.
STORE_NODE = "quad-7"
STORE_OBJECTS = ((0x1801, 5, "u16"), (0x2001, 1, "u16"), (0x6132, 1, "u8"))
SAVE_ALL = 0x65766173  # "save", CiA 301 §7.5.2.13
SETTLE_TIMEOUT = 60.0  # seconds for every node to be back and operational: a bound, not a goal


def generation_values(g: int) -> Tuple[int, int, int]:
    return 1000 + g % 1000, 1000 + g % 2000, g % 10


def proc_figures(pid: int) -> Tuple[int, int]:
    """(RSS in KiB, open descriptors) of a process."""
    rss = 0
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1])
    return rss, len(os.listdir(f"/proc/{pid}/fd"))


@dataclass
class Report:
    events: Dict[str, int] = field(default_factory=dict)
    stores: int = 0
    stores_interrupted: int = 0  # the kill landed before the store's SDO answer
    values_checked: int = 0
    store_outcomes: Dict[str, int] = field(default_factory=lambda: {"old": 0, "new": 0})
    latencies_ms: List[float] = field(default_factory=list)
    flood_latencies_ms: List[float] = field(default_factory=list)
    control_failures: int = 0  # requests that failed while the orchestrator ran
    orchestrator: List[Dict[str, int]] = field(default_factory=list)  # figures per incarnation
    settle_s: List[float] = field(default_factory=list)
    leftover_processes: int = 0

    def count(self, event: str) -> None:
        self.events[event] = self.events.get(event, 0) + 1

    def lines(self) -> List[str]:
        def pct(values: List[float], p: float) -> str:
            if not values:
                return "-"
            ordered = sorted(values)
            return f"{ordered[min(len(ordered) - 1, int(p * len(ordered)))]:.1f}"
        out = ["events: " + ", ".join(f"{k} {v}" for k, v in sorted(self.events.items()))]
        out.append(f"stores: {self.stores} ({self.stores_interrupted} interrupted by the kill), "
                   f"{self.values_checked} values checked after restarts: came back from the old save "
                   f"{self.store_outcomes['old']}, from the new {self.store_outcomes['new']}, mixed 0")
        out.append(f"control API latency (status, ms): p50 {pct(self.latencies_ms, 0.5)} p99 {pct(self.latencies_ms, 0.99)} "
                   f"over {len(self.latencies_ms)} requests; under the babbling idiot: p50 "
                   f"{pct(self.flood_latencies_ms, 0.5)} p99 {pct(self.flood_latencies_ms, 0.99)} "
                   f"({len(self.flood_latencies_ms)}); failed while running: {self.control_failures}")
        for i, o in enumerate(self.orchestrator):
            out.append(f"orchestrator {i + 1}: RSS {o['rss_start'] / 1024:.1f} -> {o['rss_end'] / 1024:.1f} MiB "
                       f"(max {o['rss_max'] / 1024:.1f}), descriptors {o['fds_start']} -> {o['fds_end']} "
                       f"(max {o['fds_max']})")
        if self.settle_s:
            out.append(f"back to all operational: median {statistics.median(self.settle_s):.1f} s, "
                       f"max {max(self.settle_s):.1f} s over {len(self.settle_s)} events")
        out.append(f"node processes left behind: {self.leftover_processes}")
        return out


class Prober(threading.Thread):
    """Asks the control API for its status on its own connection, every 100 ms, and keeps the
    latencies; samples the orchestrator's RSS and descriptors."""

    def __init__(self, report: Report) -> None:
        super().__init__(daemon=True)
        self.report = report
        self.control: Optional[str] = None
        self.pid: Optional[int] = None
        self.flooding = False
        self.stopped = threading.Event()
        self.lock = threading.Lock()
        self.figures: Dict[str, int] = {}

    def attach(self, control: str, pid: int) -> None:
        with self.lock:
            self.control, self.pid = control, pid
            rss, fds = proc_figures(pid)
            self.figures = {"rss_start": rss, "rss_end": rss, "rss_max": rss, "fds_start": fds, "fds_end": fds,
                            "fds_max": fds}

    def final_sample(self) -> None:
        """The incarnation's end figures, once what the last event left has had a second to go."""
        time.sleep(1.0)
        with self.lock:
            if self.pid is None or not self.figures:
                return
            try:
                rss, fds = proc_figures(self.pid)
            except OSError:
                return
            self.figures["rss_end"], self.figures["fds_end"] = rss, fds

    def detach(self) -> None:
        with self.lock:
            if self.figures:
                self.report.orchestrator.append(dict(self.figures))
            self.control, self.pid, self.figures = None, None, {}

    def run(self) -> None:
        client: Optional[ControlClient] = None
        endpoint = None
        while not self.stopped.wait(0.1):
            with self.lock:
                control, pid = self.control, self.pid
            if control is None or pid is None:
                continue
            if client is None or endpoint != control:
                if client is not None:
                    client.close()
                client, endpoint = ControlClient(control, timeout=10.0), control
            start = time.monotonic()
            try:
                client.call(pb.Request(status=pb.StatusRequest()))
                ms = (time.monotonic() - start) * 1000
                (self.report.flood_latencies_ms if self.flooding else self.report.latencies_ms).append(ms)
            except CanfleetError:
                with self.lock:
                    if self.pid == pid and self.control == control:
                        self.report.control_failures += 1
                continue
            try:
                rss, fds = proc_figures(pid)
            except OSError:
                continue
            with self.lock:
                if self.pid == pid and self.figures:
                    f = self.figures
                    f["rss_end"], f["fds_end"] = rss, fds
                    f["rss_max"], f["fds_max"] = max(f["rss_max"], rss), max(f["fds_max"], fds)
        if client is not None:
            client.close()


class Chaos:
    def __init__(self, folder: Path, seed: int, log: Callable[[str], None] = print) -> None:
        self.folder = folder
        self.state = folder / "state"
        self.random = random.Random(seed)
        self.log = log
        self.report = Report()
        self.prober = Prober(self.report)
        self.fleet: Optional[Fleet] = None
        self.generation = 0  # the last save asked for
        self.stored_values: Optional[Tuple[int, int, int]] = None  # what the node holds in its files
        self.node_pids: List[int] = []
        self.socketcand_ports: Dict[str, int] = {}

    # -- the fleet -----------------------------------------------------------------------------
    def topology(self) -> Path:
        """chaos.textproto with a socketcand endpoint on each bus (free ports), so that hostile
        clients reach every kind of port."""
        path = self.folder / "chaos.textproto"
        if not path.exists():
            text = TOPOLOGY.read_text().replace('"../../../topologies/eds/', f'"{HERE.parents[2]}/topologies/eds/')
            for bus in ("can0", "can1"):
                self.socketcand_ports[bus] = _free_port()
                text = text.replace(f'bus {{ name: "{bus}" ', f'bus {{ name: "{bus}" socketcand_port: {self.socketcand_ports[bus]} ', 1)
            path.write_text(text)
        return path

    def up(self) -> None:
        self.fleet = Fleet.up(self.topology(), state_dir=self.state, log_level="info", ready_timeout=120)
        assert self.fleet.pid is not None
        self.settle("start")
        self.prober.attach(self.fleet.control, self.fleet.pid)

    def down(self) -> None:
        self.prober.detach()
        if self.fleet is not None:
            self.fleet.close()
            self.fleet = None

    def statuses(self) -> List[pb.NodeStatus]:
        assert self.fleet is not None
        return list(self.fleet.status().nodes)

    def settle(self, after: str) -> None:
        """Every node attached and operational (an NMT start when a consumer that lost a heartbeat
        went pre-operational, as a master would send), within SETTLE_TIMEOUT."""
        assert self.fleet is not None
        start = time.monotonic()
        last_start = 0.0
        while True:
            nodes = self.statuses()
            waiting = [f"{n.name}({n.process},{n.nmt_state})" for n in nodes
                       if not (n.process == "running" and n.attached and n.nmt_state == "operational")]
            if not waiting:
                break
            if time.monotonic() - start > SETTLE_TIMEOUT:
                raise AssertionError(f"after {after}: not every node back and operational within "
                                     f"{SETTLE_TIMEOUT:g} s: {' '.join(waiting)}")
            if time.monotonic() - last_start > 3 and all(n.process == "running" and n.attached for n in nodes):
                self.fleet.nmt("start")
                last_start = time.monotonic()
            time.sleep(0.2)
        self.report.settle_s.append(time.monotonic() - start)
        self.node_pids = [n.pid for n in nodes if n.pid]

    # -- the events ----------------------------------------------------------------------------
    def kill_node(self) -> None:
        node = self.random.choice(self.statuses())
        os.kill(node.pid, signal.SIGKILL)
        self.report.count("node killed (kill -9)")
        self.wait_restarted(node.name, node.pid)
        self.settle(f"kill -9 of {node.name}")

    def wait_restarted(self, name: str, old_pid: int) -> None:
        end = time.monotonic() + SETTLE_TIMEOUT
        while time.monotonic() < end:
            n = next(n for n in self.statuses() if n.name == name)
            if n.pid and n.pid != old_pid and n.process == "running":
                return
            time.sleep(0.1)
        raise AssertionError(f"{name} was not restarted after its process was killed")

    def store_and_kill(self) -> None:
        """A save of new values into all three groups, the node killed at a random moment around
        it; after the restart the values must be one save's: the last one that answered (or the
        defaults before any), or this one."""
        assert self.fleet is not None
        node = self.fleet.node(STORE_NODE)
        if self.stored_values is None:
            self.stored_values = self.read_store_objects()  # the defaults: nothing saved yet
        self.generation += 1
        new_values = generation_values(self.generation)
        for (index, sub, kind), value in zip(STORE_OBJECTS, new_values):
            node.sdo_write(index, sub, value, kind)
        pid = next(n.pid for n in self.statuses() if n.name == STORE_NODE)
        answered = threading.Event()

        def save() -> None:
            try:
                node.sdo_write(0x1010, 1, SAVE_ALL, "u32")
                answered.set()
            except CanfleetError:
                pass  # killed before it answered

        saver = threading.Thread(target=save)
        saver.start()
        time.sleep(self.random.uniform(0.0, 0.012))  # a store takes a few ms: three files, fsyncs
        os.kill(pid, signal.SIGKILL)
        saver.join(timeout=30)
        self.report.stores += 1
        if not answered.is_set():
            self.report.stores_interrupted += 1
        self.report.count("store interrupted by kill -9")
        self.wait_restarted(STORE_NODE, pid)
        self.settle(f"kill -9 of {STORE_NODE} while it stored")
        values = self.read_store_objects()
        self.report.values_checked += len(values)
        if values == new_values:
            self.report.store_outcomes["new"] += 1
            self.stored_values = values
        elif values == self.stored_values:
            if answered.is_set():
                raise AssertionError(f"{STORE_NODE} answered the save of {new_values} but came back with the "
                                     f"previous save's {values}")
            self.report.store_outcomes["old"] += 1
        else:
            raise AssertionError(f"{STORE_NODE} came back with {values}: neither the previous save "
                                 f"{self.stored_values} nor the new one {new_values} (a mix of saves?)")

    def read_store_objects(self) -> Tuple[int, int, int]:
        assert self.fleet is not None
        node = self.fleet.node(STORE_NODE)
        a, b, c = (int(node.sdo_read(i, s, k)) for i, s, k in STORE_OBJECTS)
        return a, b, c

    def power_cycle(self) -> None:
        assert self.fleet is not None
        node = self.random.choice(self.statuses())
        self.fleet.inject("power-cycle", node=node.name)
        self.report.count("power cycle")
        self.wait_restarted(node.name, node.pid)
        self.settle(f"power cycle of {node.name}")

    def babbling_idiot(self) -> None:
        assert self.fleet is not None
        node = self.random.choice(self.statuses())
        self.prober.flooding = True
        try:
            self.fleet.inject("babbling-idiot", node=node.name, duration_ms=5000)
            self.report.count("babbling idiot (5 s)")
            time.sleep(5.5)
        finally:
            self.prober.flooding = False
        self.settle(f"babbling idiot {node.name}")

    def hostile_clients(self) -> None:
        """Silent connections, garbage and a client that never reads, on every port."""
        assert self.fleet is not None
        ports: List[Callable[[], socket.socket]] = [
            lambda port=port: socket.create_connection(("127.0.0.1", port), timeout=5)  # type: ignore[misc]
            for port in [int(self.fleet.control.rsplit(":", 1)[1])] + list(self.socketcand_ports.values())]
        broker = self.fleet.broker or ""
        if broker.startswith("tcp://"):
            ports.append(lambda: socket.create_connection(("127.0.0.1", int(broker.rsplit(":", 1)[1])), timeout=5))
        elif broker.startswith("unix://"):
            ports.append(lambda: _unix_connection(broker[len("unix://"):]))
        held: List[socket.socket] = []
        try:
            for connect in ports:
                for _ in range(30):  # silent
                    held.append(connect())
                garbage = connect()
                garbage.sendall(bytes(self.random.getrandbits(8) for _ in range(8192)))
                held.append(garbage)
            # a socketcand client that asks for every frame and never reads
            for bus, port in self.socketcand_ports.items():
                s = socket.create_connection(("127.0.0.1", port), timeout=5)
                s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
                s.sendall(f"< open {bus} >< rawmode >".encode())
                held.append(s)
            self.report.count("hostile clients (silent, garbage, never reading)")
            time.sleep(3)
            self.fleet.status()  # the control API answers meanwhile
        finally:
            for s in held:
                s.close()
        self.settle("hostile clients")

    def kill_orchestrator(self) -> None:
        assert self.fleet is not None and self.fleet.pid is not None
        pids = [n.pid for n in self.statuses() if n.pid]
        self.prober.final_sample()
        os.kill(self.fleet.pid, signal.SIGKILL)
        self.report.count("orchestrator killed (kill -9)")
        self.prober.detach()
        # Its nodes go with it (PR_SET_PDEATHSIG): none may be left behind.
        end = time.monotonic() + 15
        while time.monotonic() < end and any(_alive(p) for p in pids):
            time.sleep(0.1)
        self.report.leftover_processes += sum(1 for p in pids if _alive(p))
        try:
            self.fleet.close()
        except CanfleetError:
            pass
        self.fleet = None
        self.up()

    # -- the run -------------------------------------------------------------------------------
    def run(self, duration_s: float) -> Report:
        self.prober.start()
        self.up()
        events: List[Tuple[Callable[[], None], int]] = [
            (self.kill_node, 25), (self.store_and_kill, 25), (self.power_cycle, 12), (self.babbling_idiot, 12),
            (self.hostile_clients, 16), (self.kill_orchestrator, 5)]
        end = time.monotonic() + duration_s
        done_orchestrator = False
        try:
            while time.monotonic() < end:
                left = end - time.monotonic()
                if not done_orchestrator and left < duration_s / 2:
                    event = self.kill_orchestrator  # at least once a run
                else:
                    event = self.random.choices([e for e, _ in events], [w for _, w in events])[0]
                done_orchestrator |= event == self.kill_orchestrator
                self.log(f"chaos: {event.__name__} ({left:.0f} s left)")
                event()
            # the end: the fleet stops cleanly, and nothing is left running
            self.prober.final_sample()
            pids = list(self.node_pids)
            self.down()
            self.report.leftover_processes += sum(1 for p in pids if _alive(p))
        finally:
            self.prober.stopped.set()
            self.prober.join(timeout=15)
            if self.fleet is not None:
                self.down()
        return self.report


def _unix_connection(path: str) -> socket.socket:
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.settimeout(5)
    s.connect(path)
    return s


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


if __name__ == "__main__":
    import argparse
    import tempfile
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--duration", type=float, default=3600, help="seconds of chaos (default an hour)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--folder", type=Path, default=None)
    args = p.parse_args()
    folder = args.folder or Path(tempfile.mkdtemp(prefix="canfleet-chaos-"))
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    report = Chaos(folder, args.seed).run(args.duration)
    print(f"chaos: {args.duration:g} s, seed {args.seed}, state {folder}, wall {time.monotonic() - t0:.0f} s")
    for line in report.lines():
        print("chaos: " + line)
