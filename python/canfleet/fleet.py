"""Fleet control: start a fleet (`Fleet.up`) or attach to a running one (`Fleet.attach`), and drive
it through the orchestrator's control API - status, faults, simulated I/O, SDO, NMT, captures.

    with Fleet.up("topologies/examples/heartbeat-loss.textproto") as fleet:
        quad6 = fleet.node("quad-6")
        quad6.sdo_write(0x1017, 0, 1000, "u16")
        with fleet.inject("heartbeat-loss", node="quad-5"):
            ...
        print(quad6.io_get("OUT1.current_mA").value)

The shape follows python-canopen's Network/RemoteNode: a Fleet holds Nodes by name; every refusal
of the orchestrator is an OrchestratorError carrying its message.
"""
from __future__ import annotations

import atexit
import os
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time as _time
import weakref
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Dict, List, Literal, Mapping, Optional, Union

from . import process, virtual
from . import clock as clock_module
from .clock import Clock
from ._proto import control as pb
from .control import ControlClient
from .errors import (CanfleetError, FleetStartError, NodeDiedError, NotReachableError, OrchestratorError,
                     TopologyError)

TimeMode = Literal["real", "virtual"]
SdoValue = Union[int, float, bool, str, bytes]

READY_TIMEOUT = 60.0  # seconds; a bound, not an expectation (canfleet test's --ready-timeout)
STOP_TIMEOUT = 30.0

_NMT_ACTIONS: Dict[str, int] = {
    "start": pb.NMT_START, "operational": pb.NMT_START,
    "stop": pb.NMT_STOP, "stopped": pb.NMT_STOP,
    "preop": pb.NMT_PREOP, "pre-operational": pb.NMT_PREOP,
    "reset": pb.NMT_RESET, "reset-node": pb.NMT_RESET,
    "reset-comm": pb.NMT_RESET_COMM, "reset-communication": pb.NMT_RESET_COMM,
}
_PROCESS_FAULTS = {pb.KILL, pb.RESTART, pb.POWER_CYCLE}
_INT_TYPES = {"i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64"}
_SDO_TYPES = _INT_TYPES | {"b", "r32", "r64", "vs", "os", "d"}


@dataclass(frozen=True)
class IoValue:
    """One simulated signal of a node (node/devices/simulated_io.hpp): its value as text, without
    the unit ("1800"), its unit ("mV"; empty for bool and enum signals), and whether it is an input."""
    name: str
    value: str
    unit: str
    input: bool

    def __float__(self) -> float:
        return float(self.value)

    def __int__(self) -> int:
        return int(self.value)


_FAULT_KINDS: Dict[str, int] = {v.name: v.number for v in pb.DESCRIPTOR.enum_types_by_name["FaultKind"].values
                                if v.number != 0}


def fault_kind(kind: Union[str, int]) -> int:
    """FaultKind of "bus-off", "BUS_OFF" or pb.BUS_OFF. Raises ValueError listing the kinds."""
    if isinstance(kind, int):
        if kind not in _FAULT_KINDS.values():
            raise ValueError(f"unknown fault kind {kind}")
        return kind
    name = kind.strip().upper().replace("-", "_")
    if name in _FAULT_KINDS:
        return _FAULT_KINDS[name]
    kinds = ", ".join(k.lower().replace("_", "-") for k in _FAULT_KINDS)
    raise ValueError(f"unknown fault kind {kind!r} (kinds: {kinds})")


def fault_spec(kind: Union[str, int], **options: Any) -> pb.FaultSpec:
    """A FaultSpec from keyword options: the FaultSpec fields by name (node, bus, receivers, cob_id,
    mask, extended, probability, seed, delay_ms, jitter_ms, duration_ms, count, groups,
    manual_recovery, label), or `delay`, `jitter`, `duration` in seconds. Which kind takes which
    option is the orchestrator's table (orchestrator/control/fault_kinds.cpp): it refuses, with a
    reason, an option a kind does not take. Raises TypeError for an option that does not exist."""
    spec = pb.FaultSpec()
    spec.kind = fault_kind(kind)  # type: ignore[assignment]
    for seconds, field in (("delay", "delay_ms"), ("jitter", "jitter_ms"), ("duration", "duration_ms")):
        if seconds in options:
            value = options.pop(seconds)
            if field in options:
                raise TypeError(f"give {seconds} (s) or {field}, not both")
            options[field] = int(round(float(value) * 1000))
    for key, value in options.items():
        if key == "kind" or key not in pb.FaultSpec.DESCRIPTOR.fields_by_name:
            raise TypeError(f"fault option {key!r} does not exist")
        if value is None:
            continue
        if key == "receivers":
            spec.receivers.extend([value] if isinstance(value, str) else value)
        elif key == "groups":
            for group in value:
                spec.groups.add().nodes.extend(group)
        else:
            setattr(spec, key, value)
    return spec


class Fault:
    """An injected fault; `clear()` ends it (for a lasting kind). Usable as a context manager that
    clears it at exit."""

    def __init__(self, fleet: "Fleet", injected: pb.FaultInjected, spec: pb.FaultSpec) -> None:
        self.fleet = fleet
        self.id: int = injected.fault_id
        self.summary: str = injected.summary
        self.spec = spec

    def clear(self) -> str:
        """Ends the fault. Raises OrchestratorError when it is no longer active (expired, cleared,
        or a one-shot fault)."""
        return self.fleet._call(pb.Request(fault_clear=pb.FaultClear(fault_id=self.id))).done.detail

    def status(self) -> pb.FaultStatus:
        """Its entry in the fault event log (state "active", "expired", "cleared", "done"; hits)."""
        for f in self.fleet.faults(include_ended=True):
            if f.fault_id == self.id:
                return f
        raise OrchestratorError(f"fault {self.id} is not in the fault log")

    def __enter__(self) -> "Fault":
        return self

    def __exit__(self, *exc: object) -> None:
        if self.status().state == "active":
            self.clear()

    def __repr__(self) -> str:
        return f"<Fault {self.id}: {self.summary}>"


class Capture:
    """A capture the orchestrator writes (pcap or candump log); `stop()` closes the file."""

    def __init__(self, fleet: "Fleet", capture_id: int, bus: str, path: Path) -> None:
        self.fleet = fleet
        self.id = capture_id
        self.bus = bus
        self.path = path
        self.stopped = False

    def stop(self) -> None:
        if not self.stopped:
            self.fleet._call(pb.Request(capture_stop=pb.CaptureStop(capture_id=self.id)))
            self.stopped = True

    def __repr__(self) -> str:
        return f"<Capture {self.id}: {self.bus} -> {self.path}>"


class Node:
    """A node of the fleet, by its topology name: the orchestrator acts on it (its SDO client and
    NMT master, the node's simulated I/O through the broker)."""

    def __init__(self, fleet: "Fleet", name: str) -> None:
        self.fleet = fleet
        self.name = name

    def status(self) -> pb.NodeStatus:
        for node in self.fleet.status().nodes:
            if node.name == self.name:
                return node
        raise OrchestratorError(f"no node called '{self.name}' in this fleet")

    # -- simulated I/O -----------------------------------------------------------------------
    def io_get(self, name: str) -> IoValue:
        """One signal ("OUT1.current_mA")."""
        values = self.fleet._call(pb.Request(io_get=pb.IoGet(node=self.name, name=name))).io.values
        v = values[0]
        return IoValue(v.name, v.value, v.unit, v.input)

    def io_all(self) -> Dict[str, IoValue]:
        """Every signal, in declaration order."""
        values = self.fleet._call(pb.Request(io_get=pb.IoGet(node=self.name))).io.values
        return {v.name: IoValue(v.name, v.value, v.unit, v.input) for v in values}

    def io_set(self, name: str, value: Union[int, float, bool, str]) -> IoValue:
        """Sets an input ("IN1.voltage_mV", 1800); returns it as now set."""
        text = ("true" if value else "false") if isinstance(value, bool) else str(value)
        self.fleet._call(pb.Request(io_set=pb.IoSet(node=self.name, name=name, value=text)))
        return self.io_get(name)

    # -- SDO (the orchestrator is the client) --------------------------------------------------
    def sdo_read(self, index: int, subindex: int = 0, type: Optional[str] = None, *, block: bool = False,
                 can: int = 1) -> SdoValue:
        """Reads an object. `type` (cocomm's names: b i8 i16 i32 i64 u8 u16 u32 u64 r32 r64 vs os d)
        decodes it: int, float, bool, str (vs) or bytes (os, d); without a type: the raw bytes.
        `can` is the CAN port as the manual prints it (2: the data logger's CAN2).
        Raises SdoAbortError (with .code) on an abort."""
        _check_sdo_type(type)
        request = pb.Request(sdo_read=pb.SdoRead(node=self.name, index=index, subindex=subindex,
                                                 type=type or "", block=block, port=_wire_port(can)))
        data = self.fleet._call(request).sdo
        if type is None or type in ("os", "d"):
            return bytes(data.data)
        if type in _INT_TYPES:
            return int(data.text, 0)
        if type in ("r32", "r64"):
            return float(data.text)
        if type == "b":
            return bool(data.data and data.data[0])
        return data.text

    def sdo_write(self, index: int, subindex: int, value: SdoValue, type: str, *, block: bool = False,
                  can: int = 1) -> None:
        """Writes an object as `type` (see sdo_read; `can` as there); bytes for os/d. Raises
        SdoAbortError on an abort."""
        _check_sdo_type(type)
        if isinstance(value, (bytes, bytearray)):
            text = bytes(value).hex()
        elif isinstance(value, bool):
            text = "true" if value else "false"
        else:
            text = str(value)
        self.fleet._call(pb.Request(sdo_write=pb.SdoWrite(node=self.name, index=index, subindex=subindex,
                                                          type=type, value=text, block=block,
                                                          port=_wire_port(can))))

    # -- NMT, faults ---------------------------------------------------------------------------
    def nmt(self, action: str) -> None:
        """start, stop, preop, reset, reset-comm (CiA 301 §7.2.8.3.1), to this node."""
        self.fleet.nmt(action, node=self.name)

    def inject(self, kind: Union[str, int], **options: Any) -> Fault:
        """Fleet.inject with node=this node."""
        return self.fleet.inject(kind, node=self.name, **options)

    def __repr__(self) -> str:
        return f"<Node {self.name}>"


def _wire_port(can: int) -> int:
    """The control API's 0-based port of CAN`can` (the manuals' CAN1, CAN2)."""
    if can not in (1, 2):
        raise ValueError(f"can={can!r}: CAN ports are numbered as the manuals print them, 1 (CAN1) or 2 (CAN2)")
    return can - 1


def _check_sdo_type(type: Optional[str]) -> None:
    if type is not None and type not in _SDO_TYPES:
        raise ValueError(f"SDO type {type!r}: one of {' '.join(sorted(_SDO_TYPES))}")


# Fleets started here and not yet stopped, newest last: the python-can interface's default.
_running: List["weakref.ReferenceType[Fleet]"] = []
_running_lock = threading.Lock()


def current() -> Optional["Fleet"]:
    """The newest fleet of this process that is running (started by Fleet.up or attached), if any."""
    with _running_lock:
        for ref in reversed(_running):
            fleet = ref()
            if fleet is not None and not fleet.closed:
                return fleet
    return None


@atexit.register
def _close_all() -> None:
    with _running_lock:
        fleets = [ref() for ref in _running]
    for fleet in reversed(fleets):
        if fleet is not None and not fleet.closed:
            fleet.close()


def find_binaries(bin_dir: Optional[Union[str, Path]] = None) -> Path:
    """The folder holding canfleet and canfleet-node: `bin_dir`, else $CANFLEET_BIN_DIR, else the
    folder of `canfleet` on PATH, else this checkout's build/bin."""
    candidates: List[Path] = []
    if bin_dir is not None:
        candidates = [Path(bin_dir)]
    elif os.environ.get("CANFLEET_BIN_DIR"):
        candidates = [Path(os.environ["CANFLEET_BIN_DIR"])]
    else:
        on_path = shutil.which("canfleet")
        if on_path:
            candidates.append(Path(on_path).parent)
        candidates.append(Path(__file__).resolve().parents[2] / "build" / "bin")
    for folder in candidates:
        if all(os.access(folder / tool, os.X_OK) for tool in ("canfleet", "canfleet-node")):
            return folder.resolve()
    raise CanfleetError("canfleet and canfleet-node not found in " + ", ".join(map(str, candidates)) +
                        " (build them, or pass bin_dir / set CANFLEET_BIN_DIR)")


def tail(path: Optional[Path], lines: int = 40) -> str:
    if path is None:
        return "(no log)"
    try:
        text = path.read_text(errors="replace").splitlines()
    except OSError:
        return f"(no {path})"
    return "\n".join(text[-lines:])


class Fleet:
    """A running fleet, reached through its control API. Make one with Fleet.up(...) (starts and
    owns it) or Fleet.attach(...) (a fleet running elsewhere)."""

    def __init__(self, control: str, *, broker: Optional[str] = None, timeout: float = 30.0) -> None:
        self.control = control
        self.broker = broker
        self.client = ControlClient(control, timeout)
        self.closed = False
        self.topology: Optional[Path] = None
        self.time: TimeMode = "real"
        self.seed: Optional[int] = None
        self.state_dir: Optional[Path] = None
        self.log_path: Optional[Path] = None
        #: delete the private state folder at close (Fleet.up's temporary one); the pytest plugin
        #: keeps it when a test failed, so the paths in its report stay valid.
        self.remove_state_at_close = False
        self.captures: List[Capture] = []
        #: Virtual time driven by this process (Fleet.up(time="virtual"), or attached to a fleet
        #: started with `canfleet up --driven`): the fleet's simulated clock. None in real time.
        self.clock: Optional[Clock] = None
        self._owns_clock = False
        self._proc: Optional["subprocess.Popen[bytes]"] = None
        self._log_file: Optional[Any] = None
        self._restarts: Dict[str, int] = {}
        self._expected_exits: set[str] = set()
        with _running_lock:
            _running.append(weakref.ref(self))

    # -- making one ----------------------------------------------------------------------------
    @classmethod
    def attach(cls, control: str, *, broker: Optional[str] = None, timeout: float = 30.0) -> "Fleet":
        """A fleet running elsewhere (`canfleet up`), at its control endpoint (tcp://HOST:PORT).
        `broker` is its node endpoint, for the python-can interface (the `broker` line of
        `canfleet up --ready-file`). Raises NotReachableError when no orchestrator answers."""
        fleet = cls(control, broker=broker, timeout=timeout)
        try:
            status = fleet.status()
        except BaseException:
            fleet.close()
            raise
        fleet.time = "virtual" if status.virtual_time else "real"
        try:
            if status.driven:
                fleet._drive(status)
        except BaseException:
            fleet.close()
            raise
        fleet._baseline(status)
        return fleet

    def _drive(self, status: pb.Status) -> None:
        virtual.install()
        existing = clock_module.active()
        if existing is not None and existing.control == self.control:
            self.clock = existing  # this process drives it already (another Fleet object): one clock
            return
        self.clock = Clock(self.control, status.now_ns, self.client.timeout)
        self._owns_clock = True

    @classmethod
    def up(cls, topology: Union[str, Path], *, time: TimeMode = "real", seed: Optional[int] = None,
           bin_dir: Optional[Union[str, Path]] = None, state_dir: Optional[Union[str, Path]] = None,
           ready_timeout: float = READY_TIMEOUT, log_level: str = "info", telemetry: bool = False,
           env: Optional[Mapping[str, str]] = None) -> "Fleet":
        """Starts the fleet of `topology` on private endpoints (control on a free TCP port, nodes on a
        Unix socket in its state folder) and returns once every node has booted and been configured.

        - time: "real", or "virtual": the fleet's time then runs only inside this process's waits
          (fleet.run, run_until, expect, control requests, python-can recv, python-canopen's
          timeouts), in simulated seconds, deterministically (python/README.md "Virtual time").
        - seed: seeds the faults that give no seed of their own (the topology's time.seed otherwise).
        - state_dir: node state, logs (orchestrator.log) and captures; default a new temporary
          folder, removed at close.
        - telemetry: publish on DDS (off by default: tests need no `canfleet top`).

        Raises before anything starts: ValueError/TypeError for a bad argument, TopologyError
        (with file, line, column) for a refused topology. FleetStartError (with the orchestrator
        log's tail) when it does not start. The orchestrator stops, with every node, when this
        process dies, whatever the cause (canfleet/process.py)."""
        if time not in ("real", "virtual"):
            raise ValueError(f"time={time!r}: 'real' or 'virtual'")
        if seed is not None and (not isinstance(seed, int) or isinstance(seed, bool) or seed < 0):
            raise ValueError(f"seed={seed!r}: a non-negative integer")
        if ready_timeout <= 0:
            raise ValueError(f"ready_timeout={ready_timeout!r}: positive seconds")
        topology = Path(topology)
        if not topology.is_file():
            raise TopologyError(f"{topology}: no such topology file")
        binaries = find_binaries(bin_dir)
        check = subprocess.run([str(binaries / "canfleet"), "check", str(topology)], capture_output=True,
                               text=True, timeout=60)
        if check.returncode != 0:
            raise TopologyError((check.stderr or check.stdout).strip())

        owned_state = state_dir is None
        state = Path(tempfile.mkdtemp(prefix="canfleet-")) if state_dir is None else Path(state_dir)
        state.mkdir(parents=True, exist_ok=True)
        state = state.resolve()
        socket_path = state / "broker.sock"
        listen = f"unix://{socket_path}" if len(str(socket_path)) < 100 else "tcp://127.0.0.1:0"
        ready = state / "ready"
        ready.unlink(missing_ok=True)  # a state folder used again: the last run's "state ready"
        log_path = state / "orchestrator.log"
        args = [str(binaries / "canfleet"), "up", str(topology.resolve()), "--ready-file", str(ready),
                "--control", "tcp://127.0.0.1:0", "--listen", listen, "--state-dir", str(state / "nodes"),
                "--capture-dir", str(state / "captures"),
                "--time", time, "--log-level", log_level]
        if time == "virtual":
            args.append("--driven")
        if seed is not None:
            args += ["--seed", str(seed)]
        if not telemetry:
            args.append("--no-telemetry")
        child_env = dict(os.environ if env is None else env)
        child_env.pop("CANFLEET_CONTROL", None)  # our --control wins anyway; keep the log unambiguous
        log_file = open(log_path, "wb")
        try:
            proc = process.spawn_tied(args, stdin=subprocess.DEVNULL, stdout=log_file, stderr=subprocess.STDOUT,
                                      env=child_env, cwd=str(state))
        except BaseException:
            log_file.close()
            raise
        try:
            control, broker = _wait_ready(proc, ready, log_path, ready_timeout)
            fleet = cls(control, broker=broker)
        except BaseException:
            _stop_process(proc, None)
            log_file.close()
            raise
        fleet._proc = proc
        fleet._log_file = log_file
        fleet.topology = topology
        fleet.time = time
        fleet.seed = seed
        fleet.state_dir = state
        fleet.log_path = log_path
        fleet.remove_state_at_close = owned_state
        try:
            status = fleet.client.call(pb.Request(status=pb.StatusRequest())).status
            if time == "virtual":
                fleet._drive(status)
            fleet._baseline(status)
        except BaseException:
            fleet.close()
            raise
        return fleet

    # -- requests ------------------------------------------------------------------------------
    def _call(self, request: pb.Request) -> pb.Response:
        if self.closed:
            raise CanfleetError("this fleet is closed")
        if self.clock is not None:
            return self.clock.call(request)
        return self.client.call(request)

    # -- time ----------------------------------------------------------------------------------
    @property
    def now(self) -> float:
        """The fleet's time in seconds: simulated (exact) in virtual time, its uptime in real time."""
        if self.clock is not None:
            return self.clock.now
        return self.status().uptime_s

    def run(self, seconds: float) -> float:
        """Lets the fleet run `seconds` (simulated in virtual time, exactly; wall-clock in real time)
        and returns fleet.now. In virtual time other threads of this process that wait (a Notifier,
        a python-canopen timeout) wake at their own simulated times meanwhile."""
        if not isinstance(seconds, (int, float)) or isinstance(seconds, bool) or seconds < 0:
            raise ValueError(f"seconds={seconds!r}: non-negative seconds")
        if self.clock is not None:
            self.clock.sleep(seconds)
            return self.clock.now
        _time.sleep(seconds)
        return self.now

    def run_until(self, predicate: Callable[[], Any], timeout: float, step: float = 0.01) -> Any:
        """Runs the fleet in steps of `step` seconds until `predicate()` is true (returns its value)
        or `timeout` seconds passed (returns its last, false value). Simulated seconds in virtual
        time: the answer is the same on every run."""
        if timeout < 0 or step <= 0:
            raise ValueError("timeout must be >= 0 and step > 0 (seconds)")
        if self.clock is None:
            end = _time.monotonic() + timeout
            while not (value := predicate()) and _time.monotonic() < end:
                _time.sleep(step)
            return value
        end_ns = self.clock.deadline_ns(timeout)
        assert end_ns is not None
        while not (value := predicate()):
            left = end_ns - self.clock.now_ns
            if left <= 0:
                return value
            self.clock.sleep(min(step, left / 1e9))
        return value

    def expect(self, kind: str, *, within: float = 0.0, throughout: bool = False, **fields: Any) -> "Expectation":
        """Judges an expectation of a scenario's kinds (topologies/README.md "Expectations": emcy,
        no_emcy, nmt, sdo, io, frames, bus, controller) by the orchestrator's own judges, its window
        opening now and lasting `within` seconds; returns when it is decided. Fields as the topology
        file spells them: fleet.expect("emcy", node="quad-5", code=0x8130, within=3.0).
        ExpectationFailed when it failed (with what was seen instead); the Expectation (outcome,
        what was seen and when) when it passed."""
        if not re.fullmatch(r"[a-z_]+", kind):
            raise ValueError(f"kind={kind!r}: emcy, no_emcy, nmt, sdo, io, frames, bus or controller")
        if within < 0:
            raise ValueError(f"within={within!r}: non-negative seconds")
        text = f"{kind} {{ {_text_fields(fields)} }} within_ms: {round(within * 1000)}"
        if throughout:
            text += " throughout: true"
        return self.expect_text(text)

    def expect_text(self, text: str) -> "Expectation":
        """fleet.expect with the expectation in the topology's text format:
        'emcy { node: "quad-5" code: 0x8130 } within_ms: 3000'."""
        if self.clock is None:
            window = re.search(r"within_ms:\s*(\d+)", text)
            timeout = (int(window.group(1)) / 1000 if window else 0) * 2 + self.client.timeout
            response = self.client.call(pb.Request(expect=pb.ExpectRequest(expect=text)), timeout=timeout)
        else:
            response = self._call(pb.Request(expect=pb.ExpectRequest(expect=text)))
            # What was seen ends a little after the judge heard it begin (a frame's end-of-frame
            # time): return once the fleet is there, so that fleet.now >= result.decided.
            ahead = response.expect.decided_ns - self.clock.now_ns
            if ahead > 0:
                self.clock.sleep(ahead / 1e9)
        result = Expectation(response.expect)
        if result.outcome == "FAIL":
            raise ExpectationFailed(result)
        return result

    def status(self) -> pb.Status:
        """Buses, nodes (process, NMT state, controller, TEC/REC, heartbeat age, last EMCY) and the
        active faults (canfleet_control.proto, Status)."""
        return self._call(pb.Request(status=pb.StatusRequest())).status

    def node(self, name: str) -> Node:
        """The node called `name` in the topology (not checked until used)."""
        return Node(self, name)

    @property
    def nodes(self) -> List[str]:
        return [n.name for n in self.status().nodes]

    def inject(self, kind: Union[str, int], **options: Any) -> Fault:
        """Injects a fault (`canfleet fault inject`): kind "bus-off", "heartbeat-loss", "rpdo-timeout",
        "drop", "delay", "corrupt", "duplicate", "partition", "babbling-idiot", "error-passive",
        "kill", "restart", "power-cycle"; options as fault_spec() takes them. A node named that is
        no node of the topology may be a participant (a python-can bus of this fleet, by its
        `name`): bus and frame faults apply to it. Returns the Fault (clear() ends it)."""
        spec = fault_spec(kind, **options)
        if spec.kind in _PROCESS_FAULTS and spec.node:
            self._expected_exits.add(spec.node)
        injected = self._call(pb.Request(fault_inject=spec)).fault_injected
        return Fault(self, injected, spec)

    def faults(self, include_ended: bool = False) -> List[pb.FaultStatus]:
        return list(self._call(pb.Request(fault_list=pb.FaultListRequest(include_ended=include_ended))).faults.faults)

    def clear_faults(self) -> str:
        """Clears every active fault."""
        return self._call(pb.Request(fault_clear=pb.FaultClear())).done.detail

    def nmt(self, action: str, node: Optional[str] = None) -> None:
        """An NMT command (start, stop, preop, reset, reset-comm) to `node`, or to every node."""
        try:
            value = _NMT_ACTIONS[action.lower()]
        except KeyError:
            raise ValueError(f"NMT action {action!r}: one of start, stop, preop, reset, reset-comm") from None
        self._call(pb.Request(nmt=pb.NmtCommand(action=value, node=node or "")))  # type: ignore[arg-type]

    def capture(self, bus: str, path: Optional[Union[str, Path]] = None, format: str = "pcap") -> Capture:
        """Starts a capture of `bus` (pcap, LINKTYPE 227, or "candump"), written by the orchestrator
        to a new file inside the fleet's folders: `path` relative (default <bus>-<n>.<ext>) goes to
        its capture folder (<state>/captures, or `canfleet up --capture-dir`); an absolute `path`
        must be inside that or the state folder (orchestrator/fleet/capture_path.hpp). The
        Capture's `path` is where the file is."""
        if format not in ("pcap", "candump"):
            raise ValueError(f"capture format {format!r}: pcap or candump")
        if path is None:
            path = f"{bus}-{os.getpid()}-{len(self.captures) + 1}.{'pcap' if format == 'pcap' else 'log'}"
        started = self._call(pb.Request(capture_start=pb.CaptureStart(
            bus=bus, path=str(path), format=format))).capture
        capture = Capture(self, started.capture_id, bus, Path(started.path))
        self.captures.append(capture)
        return capture

    # -- node processes ------------------------------------------------------------------------
    def _baseline(self, status: pb.Status) -> None:
        self._restarts = {n.name: n.restarts for n in status.nodes}

    def dead_nodes(self) -> List[NodeDiedError]:
        """Node processes that ended, or ended and were restarted, since the fleet was ready,
        except those a process fault of this Fleet (kill, restart, power-cycle) concerned."""
        found = []
        for node in self.status().nodes:
            if node.name in self._expected_exits:
                continue
            if node.process == "exited":
                found.append(NodeDiedError(node.name, node.detail or "exited"))
            elif node.restarts > self._restarts.get(node.name, 0) or node.process == "restarting":
                # The status forgets the exit status once the node runs again; the log keeps it
                # ("quad-5: process ended (signal 9 (Killed)); restarting in 500 ms (restart 1)").
                how = node.detail if node.process == "restarting" else self._logged_end(node.name)
                found.append(NodeDiedError(node.name, f"{how or 'its process ended'}; restarted by the "
                                                      f"orchestrator ({node.restarts} restarts)"))
        return found

    def _logged_end(self, node: str) -> str:
        if self.log_path is None:
            return ""
        pattern = re.compile(re.escape(node) + r": process ended \((.*?)\)(?:;|$)")
        for line in reversed(tail(self.log_path, 2000).splitlines()):
            m = pattern.search(line)
            if m:
                return m.group(1)
        return ""

    def expect_exit(self, node: str) -> None:
        """`node`'s process may end from now on (the test stops or kills it on purpose): dead_nodes()
        and the pytest plugin no longer count it. Process faults injected through this Fleet say so
        themselves."""
        self._expected_exits.add(node)

    def check_nodes(self) -> None:
        """Raises the first NodeDiedError of dead_nodes()."""
        dead = self.dead_nodes()
        if dead:
            raise dead[0]

    def status_text(self) -> str:
        """The status as a few lines of text (pytest's report)."""
        return format_status(self.status())

    # -- ending --------------------------------------------------------------------------------
    @property
    def owned(self) -> bool:
        """Started by Fleet.up (close() stops it) rather than attached."""
        return self._proc is not None

    def close(self) -> None:
        """Stops the fleet if Fleet.up started it (every node process, then the orchestrator), else
        only disconnects. Idempotent."""
        if self.closed:
            return
        try:
            for capture in self.captures:
                if not capture.stopped:
                    try:
                        capture.stop()
                    except CanfleetError:
                        pass
            if self.clock is not None and self._owns_clock:
                self.clock.close()
            if self._proc is not None:
                _stop_process(self._proc, self.client)
        finally:
            self.closed = True
            self.client.close()
            if self._log_file is not None:
                self._log_file.close()
            if self.remove_state_at_close and self.state_dir is not None:
                shutil.rmtree(self.state_dir, ignore_errors=True)

    @property
    def returncode(self) -> Optional[int]:
        """`canfleet up`'s exit code once it ended (None while it runs, or when attached)."""
        return None if self._proc is None else self._proc.poll()

    @property
    def pid(self) -> Optional[int]:
        return None if self._proc is None else self._proc.pid

    def __enter__(self) -> "Fleet":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<Fleet {self.topology or ''} control={self.control}{' closed' if self.closed else ''}>"


@dataclass(frozen=True)
class Expectation:
    """A decided expectation (Fleet.expect): outcome "pass", "FAIL" or "skip", what it judged, what
    was seen (or seen instead, or why it was not judged), and when (fleet seconds)."""
    outcome: str
    description: str
    detail: str
    opened: float
    decided: float

    def __init__(self, result: pb.ExpectResult) -> None:
        object.__setattr__(self, "outcome", result.outcome)
        object.__setattr__(self, "description", result.description)
        object.__setattr__(self, "detail", result.detail)
        object.__setattr__(self, "opened", result.opened_ns / 1e9)
        object.__setattr__(self, "decided", result.decided_ns / 1e9)

    @property
    def passed(self) -> bool:
        return self.outcome == "pass"


class ExpectationFailed(CanfleetError, AssertionError):
    """Fleet.expect judged FAIL: the message says what was expected and what was seen instead."""

    def __init__(self, result: Expectation) -> None:
        super().__init__(f"expected {result.description}: {result.detail} (window opened at "
                         f"t={result.opened:.6f} s, decided at t={result.decided:.6f} s)")
        self.result = result


def _text_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    raise TypeError(f"{value!r}: a str, int, float or bool")


def _text_fields(fields: Mapping[str, Any]) -> str:
    parts = []
    for name, value in fields.items():
        if not re.fullmatch(r"[a-z_]+", name):
            raise ValueError(f"{name!r}: not a field name")
        for v in value if isinstance(value, (list, tuple)) else [value]:
            parts.append(f"{name}: {_text_value(v)}")
    return " ".join(parts)


def _read_ready(path: Path) -> Dict[str, str]:
    try:
        text = path.read_text()
    except OSError:
        return {}
    return dict(line.split(" ", 1) for line in text.splitlines() if " " in line)


def _wait_ready(proc: "subprocess.Popen[bytes]", ready: Path, log: Path, timeout: float) -> tuple[str, str]:
    """Polls the ready file (`state ready`) and the fleet's status (a node that exited) until the
    fleet is ready, `canfleet up` exited, or `timeout` passed."""
    deadline = _time.monotonic() + timeout
    client: Optional[ControlClient] = None
    try:
        while True:
            code = proc.poll()
            if code is not None:
                raise FleetStartError(f"canfleet up exited with {code} before the fleet was ready; "
                                      f"{log}:\n{tail(log)}", log)
            values = _read_ready(ready)
            if values.get("state") == "ready":
                return values["control"], values["broker"]
            if "control" in values:
                client = client or ControlClient(values["control"], timeout=5.0)
                try:
                    for node in client.call(pb.Request(status=pb.StatusRequest())).status.nodes:
                        if node.process == "exited":
                            raise FleetStartError(
                                f"node {node.name} exited before the fleet was ready ({node.detail}); "
                                f"{log}:\n{tail(log)}", log)
                except (NotReachableError, OrchestratorError):
                    pass
            if _time.monotonic() > deadline:
                raise FleetStartError(f"the fleet was not ready within {timeout:g} s; {log}:\n{tail(log)}", log)
            _time.sleep(0.05)
    finally:
        if client is not None:
            client.close()


def _stop_process(proc: "subprocess.Popen[bytes]", client: Optional[ControlClient]) -> None:
    """A Shutdown request (every node stops, then the orchestrator), else SIGTERM, else SIGKILL."""
    if proc.poll() is not None:
        return
    if client is not None:
        try:
            client.call(pb.Request(shutdown=pb.ShutdownRequest()), timeout=5.0)
        except CanfleetError:
            pass
    else:
        proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(timeout=STOP_TIMEOUT)
        return
    except subprocess.TimeoutExpired:
        pass
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(timeout=STOP_TIMEOUT / 2)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def format_status(status: pb.Status) -> str:
    """A compact text view of a Status: buses, nodes, active faults."""
    lines = [f"topology {status.topology}, up {status.uptime_s:.1f} s"
             f"{' (virtual time)' if status.virtual_time else ''}"]
    for bus in status.buses:
        lines.append(f"bus {bus.name}: {bus.bitrate} bit/s, {bus.ports} ports, load {bus.load_percent:.1f}%, "
                     f"{bus.frames} frames, {bus.error_frames} error frames")
    for n in status.nodes:
        emcy = (f", last EMCY {n.last_emcy.code:04X}h reg {n.last_emcy.register:02X}h ({n.emcy_count} total)"
                if n.HasField("last_emcy") else "")
        lines.append(f"node {n.name} ({n.device}) on {','.join(n.buses)}: process {n.process}"
                     f"{' (' + n.detail + ')' if n.detail else ''}, {n.restarts} restarts, nmt {n.nmt_state}, "
                     f"{n.controller} TEC {n.tec} REC {n.rec}{emcy}")
    for f in status.faults:
        lines.append(f"fault {f.fault_id} {f.state}: {f.summary} ({f.hits} hits)")
    return "\n".join(lines)


