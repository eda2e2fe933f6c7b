"""Processes and connections for the conformance suite: one `canfleet up` fleet per session, one
fresh `canfleet-node` per test, python-canopen joining the bus through the canfleet python-can
interface (the node wire protocol: canfleet/can_bus.py), in virtual or real time
(--canfleet-time, from the canfleet pytest plugin; run.sh makes virtual the default).

In virtual time the fleet is driven by this process (`canfleet up --time virtual --driven
--no-start`, attached with canfleet.Fleet.attach): its time runs only while the test waits, so
SDO timeouts, boot-up waits and absence windows are simulated seconds, and python-canopen's own
waits move to simulated time (canfleet.virtual). Every request to the fleet (simulated I/O,
status) goes through canfleet.Fleet, the one client that keeps time with the test: a `canfleet`
CLI process would wait on the wall clock for answers the stopped fleet cannot give.

The fleet's topology (written here) has one bus with a socketcand endpoint and one `external`
node per variant, and `start_nodes: false` with no heartbeat or SDO configuration: the
orchestrator then only watches, and python-canopen is the only master on the bus. The suite starts
each node process itself (`canfleet-node --name <topology name>`), so that every test gets a fresh
state directory, and so that `canfleet io set` and `canfleet fault inject` still reach it by name.
"""
from __future__ import annotations

import os
import signal
import socket
import subprocess
import threading
import time
from pathlib import Path
from typing import Callable, List, Optional

import can
import canopen

import canfleet
import canfleet.clock

# Generous bounds: they only stop a test that would otherwise hang, nothing is asserted on them.
STARTUP_TIMEOUT = 60.0
BOOT_TIMEOUT = 30.0
SDO_TIMEOUT = 5.0
WAIT_TIMEOUT = 30.0
# Bit rate of the suite's buses: the factory rate of every variant (registry.cpp, each manual).
FACTORY_BITRATE = 125_000


def _now() -> float:
    """The fleet's clock: simulated seconds when this process drives it, else the wall clock."""
    clock = canfleet.clock.active()
    return clock.now if clock is not None else time.monotonic()


def _sleep(seconds: float) -> None:
    clock = canfleet.clock.active()
    if clock is not None:
        clock.sleep(seconds)
    else:
        time.sleep(seconds)


def wait_until(predicate: Callable[[], object], timeout: float = WAIT_TIMEOUT, step: float = 0.05):
    """Polls predicate until it returns something truthy (returned) or timeout (returns None)."""
    deadline = _now() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if _now() > deadline:
            return None
        _sleep(step)


def observe_absence(seen: Callable[[], list], window: float, reason: str) -> list:
    """Watches for something that must NOT happen, for a bounded observation window; returns what
    `seen` reported (the caller asserts it is empty), at the first sighting or at the window's end.

    No event says "never": proving that a frame was not sent takes watching the bus for a while
    (simulated time in virtual time, real time otherwise). `window` (seconds) is that while, and `reason` says why it is long enough
    for this claim (e.g. "20 periods of the former 50 ms heartbeat"), so that nobody shortens it
    below what the claim needs or mistakes it for a wait on something that happens.
    """
    assert reason, "state why the window is long enough"
    deadline = _now() + window
    while True:
        found = seen()
        left = deadline - _now()
        if found or left <= 0:
            return found
        _sleep(min(0.05, left))


def free_tcp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def tail(path: Path, lines: int = 40) -> str:
    try:
        text = path.read_text(errors="replace").splitlines()
    except OSError:
        return f"(no {path})"
    return "\n".join(text[-lines:])


class Fleet:
    """`canfleet up` with a generated topology, until stop()."""

    def __init__(self, bin_dir: Path, work: Path, variants, time_mode: str = "virtual"):
        self.bin_dir = bin_dir
        self.work = work
        self.virtual = time_mode == "virtual"
        # socketcand lives in real time (refused on a virtual bus); the real-time suite keeps it
        # so that python-can's own socketcand interface keeps a test.
        self.socketcand_port = 0 if self.virtual else free_tcp_port()
        self.bus = "can0"
        self.topology = work / "conformance.textproto"
        self.topology.write_text(self._topology(variants))
        self.ready_file = work / "ready"
        self.log = work / "orchestrator.log"
        env = dict(os.environ)
        env.setdefault("CANFLEET_DDS_DOMAIN", "77")  # keep telemetry off other runs' DDS domain
        self._log_file = open(self.log, "w")
        self.proc = subprocess.Popen(
            [str(bin_dir / "canfleet"), "up", str(self.topology), "--ready-file", str(self.ready_file),
             "--control", "tcp://127.0.0.1:0", "--listen", "tcp://127.0.0.1:0", "--no-start",
             "--log-level", "debug", "--time", time_mode, *(["--driven"] if self.virtual else [])],
            stdout=self._log_file, stderr=subprocess.STDOUT, env=env, start_new_session=True)
        self.control = ""
        self.broker = ""
        self.api: Optional[canfleet.Fleet] = None
        ok = wait_until(self._read_ready, STARTUP_TIMEOUT)
        if not ok:
            self.stop()
            raise RuntimeError(f"canfleet up did not write its endpoints to {self.ready_file}:\n{tail(self.log)}")
        # The one client of the fleet: in virtual time it holds the fleet's clock.
        self.api = canfleet.Fleet.attach(self.control, broker=self.broker)
        if self.virtual and self.api.clock is None:
            self.stop()
            raise RuntimeError(f"the fleet is not driven by this process:\n{tail(self.log)}")
        # The socketcand endpoint is up once the orchestrator is: wait until it accepts.
        if not self.virtual and not wait_until(self._socketcand_accepts, STARTUP_TIMEOUT):
            self.stop()
            raise RuntimeError(f"no socketcand endpoint on port {self.socketcand_port}:\n{tail(self.log)}")

    def _topology(self, variants) -> str:
        lines = [
            "# Written by tests/conformance/harness.py: python-canopen is the master, the orchestrator",
            "# only watches (no configuration, no NMT start); the suite starts the nodes itself.",
            'name: "conformance"',
            "orchestrator { start_nodes: false }",
            # The variants' factory bit rate (every manual: 125 kbit/s): a node nobody configured is
            # commissioned for its bus, so 5B50h (the bit rate, UMAX020411A §3.4.110) reads its EDS
            # default only on a bus at the factory rate, as a device fresh from the factory would.
            f'bus {{ name: "{self.bus}" bitrate: {FACTORY_BITRATE}'
            + (f" socketcand_port: {self.socketcand_port}" if self.socketcand_port else "") + " }",
        ]
        # A device with several CAN ports has its port 1 on can0 (python-canopen's bus) and each
        # further port on a bus of its own (can1, ...) without a socketcand endpoint: the suite
        # checks port 1.
        for p in range(1, max(v.ports for v in variants)):
            lines.append(f'bus {{ name: "{self.port_bus(p)}" bitrate: {FACTORY_BITRATE} }}')
        for v in variants:
            kind = f'device: "{v.device}"' if v.device else f'eds: "{v.eds}"'
            buses = " ".join(f'bus: "{self.port_bus(p)}"' for p in range(v.ports))
            lines.append(f'node {{ name: "{v.name}" {kind} node_id: {v.node_id} {buses} external: true }}')
        return "\n".join(lines) + "\n"

    def port_bus(self, port: int) -> str:
        """The bus of a node's CAN port `port` (0-based): can0 for port 1, can1 for port 2, ..."""
        return self.bus if port == 0 else f"can{port}"

    def _read_ready(self) -> bool:
        if self.proc.poll() is not None:
            raise RuntimeError(f"canfleet up exited with {self.proc.returncode}:\n{tail(self.log)}")
        try:
            text = self.ready_file.read_text()
        except OSError:
            return False
        values = dict(line.split(" ", 1) for line in text.splitlines() if " " in line)
        if "control" not in values or "broker" not in values:
            return False
        self.control, self.broker = values["control"], values["broker"]
        return True

    def _socketcand_accepts(self) -> bool:
        try:
            with socket.create_connection(("127.0.0.1", self.socketcand_port), timeout=2) as s:
                return s.recv(64).startswith(b"< hi >")
        except OSError:
            return False

    def io_get(self, node: str, name: str) -> str:
        assert self.api is not None
        return self.api.node(node).io_get(name).value

    def io_set(self, node: str, name: str, value: str) -> None:
        assert self.api is not None
        self.api.node(node).io_set(name, value)

    def attached(self, node: str) -> bool:
        """The orchestrator's view: the (external) node has a broker connection on every port."""
        assert self.api is not None
        return any(n.name == node and n.attached for n in self.api.status().nodes)

    def stop(self) -> None:
        if self.api is not None:
            self.api.close()  # attached: disconnects (and lets go of the clock)
            self.api = None
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log_file.close()


class Frames(can.Listener):
    """Every frame python-can delivers, for checks python-canopen has no API for (boot-up,
    heartbeat state bytes, PDOs that must not be sent)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.frames: List[can.Message] = []

    def on_message_received(self, msg: can.Message) -> None:
        with self.lock:
            self.frames.append(msg)

    def since(self, start: int, can_id: Optional[int] = None) -> List[can.Message]:
        with self.lock:
            got = self.frames[start:]
        return [m for m in got if can_id is None or m.arbitration_id == can_id]

    def mark(self) -> int:
        with self.lock:
            return len(self.frames)


class NodeUnderTest:
    """A canfleet-node process of one variant, and python-canopen's view of it."""

    def __init__(self, fleet: Fleet, variant, work: Path, extra_args: Optional[List[str]] = None,
                 node_id: Optional[int] = None):
        self.fleet = fleet
        self.variant = variant
        self.work = work
        self.state_dir = work / "state"
        self.state_dir.mkdir(parents=True, exist_ok=True)
        self.extra_args = list(extra_args or [])
        self.node_id = node_id or variant.node_id
        self.log = work / "node.log"
        self.proc: Optional[subprocess.Popen] = None
        self.frames = Frames()
        self.network = canopen.Network()
        if fleet.socketcand_port:
            self.network.connect(interface="socketcand", host="127.0.0.1", port=fleet.socketcand_port,
                                 channel=fleet.bus)
        else:
            self.network.connect(interface="canfleet", channel=fleet.bus, fleet=fleet.api,
                                 name=f"python-canopen-{variant.name}")
        self.network.notifier.add_listener(self.frames)
        self.network.lss.RESPONSE_TIMEOUT = SDO_TIMEOUT
        self.remote = self.add_remote(self.node_id)

    def add_remote(self, node_id: int) -> canopen.RemoteNode:
        remote = canopen.RemoteNode(node_id, str(self.variant.eds))
        remote.sdo.RESPONSE_TIMEOUT = SDO_TIMEOUT
        self.network.add_node(remote)
        return remote

    def command(self, node_id: Optional[int] = None) -> List[str]:
        cmd = [str(self.fleet.bin_dir / "canfleet-node"), *self.variant.node_args(), "--name", self.variant.name,
               "--node-id", str(node_id or self.variant.node_id)]
        for port in range(self.variant.ports):
            cmd += ["--bus", f"{self.fleet.port_bus(port)}@{self.fleet.broker}"]
        cmd += ["--state-dir", str(self.state_dir), "--no-telemetry", "--log-level", "debug"]
        if self.fleet.virtual:
            cmd += ["--time", "virtual"]
        for io in self.variant.default_io:
            cmd += ["--io", io]
        return cmd + self.extra_args

    def start(self, expect_node_id: Optional[int] = None, cli_node_id: Optional[int] = None,
              wait: bool = True) -> None:
        """Starts the process (--node-id cli_node_id, default the variant's) and waits for its
        boot-up (CiA 301 §7.2.8.3.2.1: 700h+ID, 00h) unless wait is False."""
        bootup_id = 0x700 + (expect_node_id or self.node_id)
        mark = self.frames.mark()
        log = open(self.log, "a")
        self.proc = subprocess.Popen(self.command(cli_node_id), stdout=log, stderr=subprocess.STDOUT,
                                     start_new_session=True)
        log.close()
        self._wait_attached(True)
        if wait and not wait_until(lambda: self._seen(mark, bootup_id), BOOT_TIMEOUT):
            raise AssertionError(f"no boot-up {bootup_id:03X}#00 from {self.variant.name}:\n{tail(self.log)}")

    def _wait_attached(self, attached: bool) -> None:
        """Virtual time: waits in real time (the fleet stands still meanwhile) until the broker has
        the node process's connection (or, after a stop, has seen it go). Starting a process takes
        real time, which the fleet's simulated time must not race: a boot-up wait counted in
        simulated seconds from before the process connected would run out on a slow machine."""
        if not self.fleet.virtual:
            return
        end = time.monotonic() + STARTUP_TIMEOUT
        while self.fleet.attached(self.variant.name) != attached:
            if attached and self.proc is not None and self.proc.poll() is not None:
                raise AssertionError(f"{self.variant.name} exited with {self.proc.returncode}:\n{tail(self.log)}")
            if time.monotonic() > end:
                raise AssertionError(f"{self.variant.name} {'never attached' if attached else 'still attached'} "
                                     f"within {STARTUP_TIMEOUT:g} s:\n{tail(self.log)}")
            time.sleep(0.02)

    def _seen(self, mark: int, can_id: int) -> bool:
        if self.proc is not None and self.proc.poll() is not None:
            raise AssertionError(f"{self.variant.name} exited with {self.proc.returncode}:\n{tail(self.log)}")
        return any(bytes(m.data) == b"\x00" for m in self.frames.since(mark, can_id))

    def wait_bootup(self, mark: int, node_id: int) -> bool:
        return bool(wait_until(lambda: self._seen(mark, 0x700 + node_id), BOOT_TIMEOUT))

    def stop_process(self) -> Optional[int]:
        if self.proc is None:
            return None
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        code = self.proc.returncode
        self.proc = None
        self._wait_attached(False)
        return code

    def close(self) -> Optional[int]:
        code = self.stop_process()
        try:
            self.network.disconnect()
        except Exception:  # noqa: BLE001 - a broken connection must not hide the test's result
            pass
        return code
