"""python-can interface "canfleet": a python-can Bus that joins a fleet's virtual CAN bus as a
participant through the node wire protocol (bus/wire/canfleet_wire.proto), as a node process does -
not through socketcand:

    bus = can.Bus(interface="canfleet", channel="can0")          # inside `with Fleet.up(...)`
    network.connect(interface="canfleet", channel="can0")         # python-canopen, unchanged

- Its frames are arbitrated with the nodes' on the bus's time line (its own TX queue, like one
  controller), acknowledged and counted: it has TEC/REC and a controller state (`state`, `tec`,
  `rec`), goes error-passive and bus-off, and faults injected on it by its `name`
  (fleet.inject("bus-off", node=bus.name)) or on frames it sends or receives apply to it.
- Received frames carry the bus's timestamps: the end of the frame on the bus, as wall-clock
  seconds (HelloReply.wall_origin_ns + the record's bus time), exactly what captures and
  `canfleet dump` show for it.
- Its python-can filters become the broker's acceptance filter (Acceptance): the broker sends it no
  11-bit frame they reject. python-can still checks every frame (extended and error frames always
  pass the broker), so filtering behaves as python-can documents.

Threading: one reader thread per bus decodes what the broker sends (frames into the inbox,
controller events, pings, node requests); send() writes from the caller's thread under a lock.
recv() waits on the inbox. In real time these waits are wall-clock waits; on a fleet this process
drives in virtual time (Fleet.up(time="virtual")) the bus joins as a *driven* participant
(Hello.driven) and its waits count simulated seconds on the fleet's clock (canfleet/clock.py,
python/README.md "Virtual time").
"""
from __future__ import annotations

import collections
import itertools
import os
import socket
import threading
import time
from typing import Any, Deque, Dict, List, Optional, Tuple

import can
from can import BusState, CanInitializationError, CanOperationError

from . import endpoints, wire
from .clock import Clock
from .sim_periodic import SimCyclicSendTask
from .virtual import SimCondition
from ._proto import wire as pb
from .errors import BrokerRefusedError, CanfleetError, WireVersionError
from .framing import DelimitedReader, FramingError

CONNECT_TIMEOUT = 10.0  # seconds to connect and be answered (the broker's own Hello deadline is 10 s)

_STATES = {
    pb.CONTROLLER_STATE_ERROR_ACTIVE: BusState.ACTIVE,
    pb.CONTROLLER_STATE_ERROR_PASSIVE: BusState.PASSIVE,
    pb.CONTROLLER_STATE_BUS_OFF: BusState.ERROR,
}
_STATE_NAMES = {BusState.ACTIVE: "error-active", BusState.PASSIVE: "error-passive", BusState.ERROR: "bus-off"}
_names = itertools.count(1)


def acceptance_ids(filters: Optional[List[Any]]) -> Optional[List[int]]:
    """The 11-bit identifiers python-can `filters` let through (None: every frame). A filter
    restricted to extended frames adds none: extended frames always pass the broker."""
    if not filters:
        return None
    ids: set[int] = set()
    for f in filters:
        if f.get("extended") is True:
            continue
        can_id, mask = int(f["can_id"]), int(f["can_mask"])
        if (can_id & mask) >> 11:  # asks for bits an 11-bit identifier does not have
            continue
        if mask & 0x7FF == 0:
            return None
        ids.update(i for i in range(0x800) if (i ^ can_id) & mask == 0)
    return None if len(ids) == 0x800 else sorted(ids)


class _Inbox:
    """Received messages, waited for by recv(). The one place a Python thread waits for the bus:
    on a driven fleet (`clock`) it waits in simulated time (python/README.md, "Virtual time")."""

    def __init__(self, clock: Optional[Clock] = None) -> None:
        self._items: Deque[can.Message] = collections.deque()
        self._cond = SimCondition() if clock is not None else threading.Condition()
        self._clock = clock
        self._closed: Optional[str] = None

    def put(self, items: List[can.Message]) -> None:
        with self._cond:
            self._items.extend(items)
            self._cond.notify_all()

    def close(self, reason: str) -> None:
        with self._cond:
            if self._closed is None:
                self._closed = reason
            self._cond.notify_all()

    def get(self, timeout: Optional[float]) -> Optional[can.Message]:
        if self._clock is not None:
            return self._get_simulated(timeout)
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._cond:
            while not self._items:
                if self._closed is not None:
                    raise CanOperationError(self._closed)
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    return None
                self._cond.wait(left)
            return self._items.popleft()

    def _get_simulated(self, timeout: Optional[float]) -> Optional[can.Message]:
        clock = self._clock
        assert clock is not None
        deadline = clock.deadline_ns(timeout)
        with self._cond:
            while not self._items:
                if self._closed is not None:
                    raise CanOperationError(self._closed)
                if deadline is not None and clock.now_ns >= deadline:
                    return None
                try:
                    self._cond.wait(None if deadline is None else (deadline - clock.now_ns) / 1e9)
                except CanfleetError as e:  # the fleet went away: python-can's error for a lost bus
                    raise CanOperationError(str(e)) from None
                if clock.consume_interrupt():
                    return None
            return self._items.popleft()


class CanfleetBus(can.BusABC):
    """A python-can Bus on a canfleet fleet's bus `channel` ("can0").

    :param channel: the bus's name in the topology.
    :param broker: the broker's node endpoint (tcp://HOST:PORT or unix:///path; the `broker` line
        of `canfleet up --ready-file`). Default: `fleet`'s, else the newest running Fleet of this
        process (canfleet.current()), else $CANFLEET_BROKER.
    :param fleet: a canfleet.Fleet whose broker to join.
    :param name: the participant's name on the bus (logs, statistics, faults by node name). It
        must not be the name of a topology node. Default python-can-<pid>-<n>.
    :param bitrate: the controller's bit rate in bit/s; default: the bus's (a different rate sees
        only error frames, as a real controller would).
    :param token: the fleet's token, for a broker that listens beyond loopback; default: from
        CANFLEET_TOKEN_FILE or CANFLEET_TOKEN (canfleet.auth).
    :param receive_own_messages: also receive own frames once they were on the bus (TX
        confirmations, with their bus timestamp, is_rx False).
    :param can_filters: python-can filters; they become the broker's acceptance filter.
    """

    def __init__(self, channel: str, can_filters: Optional[Any] = None, *, broker: Optional[str] = None,
                 fleet: Optional[Any] = None, name: Optional[str] = None, bitrate: int = 0,
                 receive_own_messages: bool = False, connect_timeout: float = CONNECT_TIMEOUT,
                 token: Optional[str] = None, **kwargs: Any) -> None:
        if not isinstance(channel, str) or not channel:
            raise CanInitializationError("canfleet: channel must be the bus's name, e.g. 'can0'")
        self.channel = channel
        self.channel_info = f"canfleet bus {channel}"
        self.name = name or f"python-can-{os.getpid()}-{next(_names)}"
        self._token = token
        self.endpoint, fleet = _broker_endpoint(broker, fleet)
        #: The driven fleet's simulated clock (virtual time), else None: waits are real-time waits.
        self.clock: Optional[Clock] = fleet.clock if fleet is not None else None
        self.receive_own_messages = receive_own_messages
        self._send_lock = threading.Lock()
        self._inbox = _Inbox(self.clock)
        self._state_cond = SimCondition() if self.clock is not None else threading.Condition()
        self._pongs: Dict[int, threading.Event] = {}
        self._nonces = itertools.count(1)
        self._state = BusState.ACTIVE
        self.tec = 0
        self.rec = 0
        self._wall_origin_ns = 0
        self._closing = False
        try:
            self._sock = endpoints.connect(self.endpoint, connect_timeout, self._token)
        except (OSError, ValueError) as e:
            raise CanInitializationError(f"canfleet: no broker at {self.endpoint} ({e})") from None
        self._reader = DelimitedReader()
        try:
            reply = self._hello(int(bitrate or 0), connect_timeout)
        except BaseException:
            self._sock.close()
            raise
        self.port_id: int = reply.port_id
        self.bus_bitrate: int = reply.bitrate
        self.paced: bool = reply.mode != pb.BUS_MODE_UNPACED
        self._wall_origin_ns = reply.wall_origin_ns
        self._sock.settimeout(None)
        self._thread = threading.Thread(target=self._read_loop, name=f"canfleet-bus-{self.name}", daemon=True)
        self._thread.start()
        super().__init__(channel=channel, can_filters=can_filters, **kwargs)
        if self.clock is not None:
            self.clock.add_bus(self)

    # -- connecting ----------------------------------------------------------------------------
    def _hello(self, bitrate: int, timeout: float) -> pb.HelloReply:
        hello = pb.Hello(protocol_version=wire.PROTOCOL_VERSION, bus=self.channel, node_name=self.name,
                         node_id=0, role=pb.ROLE_NODE, tx_confirmations=self.receive_own_messages,
                         bitrate=bitrate, virtual_time=self.clock is not None, driven=self.clock is not None)
        self._sock.sendall(wire.envelope(hello=hello))
        deadline = time.monotonic() + timeout
        while True:
            body = self._reader.next()
            if body is not None:
                env = pb.Envelope()
                env.ParseFromString(body)
                kind = env.WhichOneof("body")
                if kind == "hello_reply":
                    return self._accepted(env.hello_reply)
                if kind == "error":
                    raise BrokerRefusedError(f"the broker at {self.endpoint} closed: {env.error.reason}")
                continue  # a Pong to nothing, or whatever else comes first
            left = deadline - time.monotonic()
            if left <= 0:
                raise CanInitializationError(f"canfleet: no HelloReply from {self.endpoint} within {timeout:g} s")
            self._sock.settimeout(left)
            try:
                data = self._sock.recv(65536)
            except OSError as e:
                raise CanInitializationError(f"canfleet: broker at {self.endpoint}: {e}") from None
            if not data:
                raise CanInitializationError(f"canfleet: the broker at {self.endpoint} closed the connection")
            self._reader.feed(data)

    def _accepted(self, reply: pb.HelloReply) -> pb.HelloReply:
        if reply.protocol_version != wire.PROTOCOL_VERSION:
            raise WireVersionError(wire.PROTOCOL_VERSION, reply.protocol_version, self.endpoint,
                                   reply.reason or "the broker answered in its own version")
        if not reply.accepted:
            raise BrokerRefusedError(f"the broker at {self.endpoint} refused {self.name} on {self.channel}: "
                                     f"{reply.reason}")
        return reply

    # -- python-can API ------------------------------------------------------------------------
    def send(self, msg: can.Message, timeout: Optional[float] = None) -> None:
        if msg.is_fd:
            raise CanOperationError("canfleet: CAN FD frames are not supported (classical CAN only)")
        if msg.dlc > 8 or len(msg.data) > 8:
            raise CanOperationError(f"canfleet: DLC {msg.dlc} over 8")
        if self._state is BusState.ERROR:
            raise CanOperationError(f"canfleet: {self.name}'s controller is bus-off (TEC {self.tec}): frame not sent")
        flags = ((wire.FLAG_EXTENDED if msg.is_extended_id else 0) | (wire.FLAG_REMOTE if msg.is_remote_frame else 0))
        data = b"" if msg.is_remote_frame else bytes(msg.data[:msg.dlc])
        record = wire.Record(0, msg.arbitration_id, msg.dlc, flags, data)
        payload = wire.envelope(frames=pb.FrameBatch(records=wire.encode_records([record])))
        self._write(payload)

    def _write(self, payload: bytes) -> None:
        with self._send_lock:
            if self._closing:
                raise CanOperationError("canfleet: the bus is shut down")
            try:
                self._sock.sendall(payload)
            except OSError as e:
                raise CanOperationError(f"canfleet: broker connection lost ({e})") from None

    def recv(self, timeout: Optional[float] = None) -> Optional[can.Message]:
        """python-can's recv; on a driven fleet `timeout` is simulated seconds, also across frames
        the filters reject (python-can's own loop counts those in real time)."""
        clock = self.clock
        if clock is None:
            return super().recv(timeout)
        deadline = clock.deadline_ns(timeout)
        while True:
            left = None if deadline is None else max(0, deadline - clock.now_ns) / 1e9
            msg = self._inbox.get(left)
            if msg is None:
                return None
            if self._matches_filters(msg):
                return msg

    def _send_periodic_internal(self, msgs: Any, period: float, duration: Optional[float] = None,
                                autostart: bool = True, modifier_callback: Any = None) -> Any:
        if self.clock is None:
            return super()._send_periodic_internal(msgs, period, duration, autostart, modifier_callback)
        return SimCyclicSendTask(self, self.clock, msgs, period, duration, autostart, modifier_callback)

    def _sync(self) -> None:
        """Ping and wait for the Pong: the broker has read everything sent before, and the reader
        thread has handled everything the broker sent before (the clock's barrier, real time)."""
        if self._closing:
            return
        nonce = next(self._nonces)
        done = threading.Event()
        self._pongs[nonce] = done
        try:
            self._write(wire.envelope(ping=pb.Ping(nonce=nonce)))
            while not done.wait(0.05):
                if self._closing or not self._thread.is_alive():
                    return
        except CanOperationError:
            return
        finally:
            self._pongs.pop(nonce, None)

    def _recv_internal(self, timeout: Optional[float]) -> Tuple[Optional[can.Message], bool]:
        # Never "already filtered": extended and error frames pass the broker, so python-can checks
        # every frame against the filters as well.
        return self._inbox.get(timeout), False

    def _apply_filters(self, filters: Optional[Any]) -> None:
        if not hasattr(self, "_sock"):
            return
        ids = acceptance_ids(list(filters) if filters else None)
        acceptance = pb.Acceptance(all=True) if ids is None else pb.Acceptance(ids=ids)
        self._write(wire.envelope(acceptance=acceptance))

    @property
    def state(self) -> BusState:
        """ACTIVE (error-active), PASSIVE (error-passive) or ERROR (bus-off), as the broker's model
        of this participant's controller says (ISO 11898-1 §12.1.4)."""
        return self._state

    @state.setter
    def state(self, new_state: BusState) -> None:
        raise NotImplementedError("canfleet: the controller state follows the bus (inject faults to change it)")

    @property
    def controller_state(self) -> str:
        """"error-active", "error-passive" or "bus-off", as `canfleet status` names them."""
        return _STATE_NAMES[self._state]

    def wait_for_state(self, state: BusState, timeout: float) -> bool:
        """Waits until the controller is in `state`; False when `timeout` (seconds) passed first."""
        with self._state_cond:
            return bool(self._state_cond.wait_for(lambda: self._state is state, timeout))

    def shutdown(self) -> None:
        if self._closing:
            return
        with self._send_lock:
            self._closing = True
            try:
                self._sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        if self.clock is not None:
            self.clock.remove_bus(self)
        self._thread.join(timeout=5)
        self._sock.close()
        self._inbox.close("canfleet: the bus is shut down")
        super().shutdown()

    @staticmethod
    def _detect_available_configs() -> List[Any]:
        return []

    # -- the reader thread ---------------------------------------------------------------------
    def _read_loop(self) -> None:
        reason = "canfleet: the broker closed the connection"
        try:
            while True:
                try:
                    data = self._sock.recv(65536)
                except OSError as e:
                    reason = f"canfleet: broker connection lost ({e})"
                    break
                if not data:
                    break
                self._reader.feed(data)
                while (body := self._reader.next()) is not None:
                    env = pb.Envelope()
                    env.ParseFromString(body)
                    stop = self._handle(env)
                    if stop:
                        reason = stop
                        raise StopIteration
        except StopIteration:
            pass
        except (FramingError, ValueError) as e:
            reason = f"canfleet: protocol error from the broker: {e}"
        if self._closing:
            reason = "canfleet: the bus is shut down"
        self._inbox.close(reason)

    def _handle(self, env: pb.Envelope) -> Optional[str]:
        kind = env.WhichOneof("body")
        if kind == "frames":
            self._inbox.put([self._message(r, True) for r in wire.decode_records(env.frames.records)])
        elif kind == "tx_confirm":
            if self.receive_own_messages:
                self._inbox.put([self._message(r, False) for r in wire.decode_records(env.tx_confirm.records)])
        elif kind == "controller_event":
            event = env.controller_event
            with self._state_cond:
                self._state = _STATES.get(event.state, BusState.ERROR)
                self.tec, self.rec = event.tec, event.rec
                self._state_cond.notify_all()
        elif kind == "ping":
            self._write_quietly(wire.envelope(pong=pb.Pong(nonce=env.ping.nonce)))
        elif kind == "pong":
            done = self._pongs.get(env.pong.nonce)
            if done is not None:
                done.set()
        elif kind == "node_request":
            reply = pb.NodeReply(request_id=env.node_request.request_id,
                                 error=f"{self.name} is a python-can participant: it has no simulated I/O")
            self._write_quietly(wire.envelope(node_reply=reply))
        elif kind == "error":
            return f"canfleet: the broker closed the connection: {env.error.reason}"
        elif kind == "time_grant":
            return "canfleet: a time grant to a driven participant (it is never granted time): protocol error"
        return None

    def _write_quietly(self, payload: bytes) -> None:
        try:
            self._write(payload)
        except CanOperationError:
            pass

    def _message(self, r: wire.Record, rx: bool) -> can.Message:
        return can.Message(
            timestamp=(self._wall_origin_ns + r.time_ns) / 1e9, arbitration_id=r.can_id,
            is_extended_id=bool(r.flags & wire.FLAG_EXTENDED), is_remote_frame=bool(r.flags & wire.FLAG_REMOTE),
            is_error_frame=bool(r.flags & wire.FLAG_ERROR), dlc=r.dlc, data=r.data, channel=self.channel,
            is_rx=rx, check=False)


def _broker_endpoint(broker: Optional[str], fleet: Optional[Any]) -> Tuple[str, Optional[Any]]:
    """The broker's endpoint, and the fleet it belongs to when known (its clock, in virtual time)."""
    if fleet is None:
        from .fleet import current
        fleet = current()
        if fleet is not None and broker and str(fleet.broker) != broker:
            fleet = None  # another fleet's broker
    if broker:
        return broker, fleet
    if fleet is not None:
        if not fleet.broker:
            raise CanInitializationError("canfleet: this fleet was attached without its broker endpoint "
                                         "(Fleet.attach(control, broker=...))")
        return str(fleet.broker), fleet
    env = os.environ.get("CANFLEET_BROKER")
    if env:
        return env, None
    raise CanInitializationError("canfleet: which fleet? pass broker='tcp://HOST:PORT' or fleet=..., run inside "
                                 "`with Fleet.up(...)`, or set CANFLEET_BROKER")


__all__ = ["CanfleetBus", "acceptance_ids", "CanfleetError"]
