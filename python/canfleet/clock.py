"""Simulated time of a driven fleet, as one Python process lives it (python/README.md, "Virtual time").

A fleet started with `Fleet.up(..., time="virtual")` stands still between the test's steps
(`canfleet up --driven`): its time runs only inside a ClockAdvance request of this process. The
rule this module keeps: **simulated time advances only while every Python thread that takes part
is waiting, and only up to the earliest simulated deadline any of them waits for.** So a timeout in
Python fires only when simulated time reached it, never because the machine was slow, and what a
thread does after a wait happens at an exact simulated time.

- A thread takes part from its first simulated wait (the thread that made the clock from the
  start) until it ends. While it runs between waits, time stands still.
- Every wait is one of: `SimCondition.wait` (and what is built on it: `SimQueue.get`, the bus's
  inbox, `fleet.run`), or a control request through `Clock.call`, woken by its answer.
- One waiting thread at a time runs the fleet (ClockAdvance to the earliest deadline); the broker
  ends the step early when something reaches this process (a frame for one of its buses, an answer
  to a request), at the simulated time it happened.

Only one clock is active per process (`active()`); the simulated-time versions of python-canopen's
waits (canfleet.virtual) use it.
"""
from __future__ import annotations

import itertools
import logging
import socket
import threading
import time
from typing import Any, Dict, List, Optional, Set

from . import endpoints
from ._proto import control as pb
from .errors import CanfleetError, NotReachableError, SdoAbortError
from .framing import DelimitedReader, FramingError, delimited

FOREVER_NS = 1 << 62  # "no deadline": the step runs until something reaches this process
_POLL_S = 0.05  # real seconds between checks for participant threads that ended without a word
_STALL_S = 30.0  # real seconds of standing still with waiters before saying which threads hold time
_log = logging.getLogger("canfleet.clock")

_active: Optional["Clock"] = None
_active_lock = threading.Lock()


def active() -> Optional["Clock"]:
    """The driven fleet's clock of this process, or None (real time)."""
    return _active


class _Waiter:
    __slots__ = ("thread", "deadline_ns", "woken")

    def __init__(self, thread: threading.Thread, deadline_ns: Optional[int]) -> None:
        self.thread = thread
        self.deadline_ns = deadline_ns
        self.woken = False


class _Pending:
    __slots__ = ("waiter", "response", "error")

    def __init__(self, waiter: _Waiter) -> None:
        self.waiter = waiter
        self.response: Optional[pb.Response] = None
        self.error: Optional[BaseException] = None


class Clock:
    """The simulated clock of the driven fleet at `control` (its control endpoint)."""

    def __init__(self, control: str, now_ns: int, timeout: float = 30.0) -> None:
        global _active
        self.control = control
        self.now_ns = now_ns
        self.timeout = timeout
        self.advances = 0  # ClockAdvance steps run (statistics)
        self._cv = threading.Condition()
        self._waiting: Dict[threading.Thread, _Waiter] = {}
        self._participants: Set[threading.Thread] = {threading.current_thread()}
        self._advancing = False
        self._closed: Optional[str] = None
        self._buses: List[Any] = []
        self._interrupted: Set[threading.Thread] = set()  # CanfleetBus: flushed before and after each step
        try:
            self._sock = endpoints.connect(control, timeout)
        except OSError as e:
            raise NotReachableError(f"no orchestrator at {control} ({e.strerror or e})") from None
        self._sock.settimeout(None)
        self._send_lock = threading.Lock()
        self._ids = itertools.count(1)
        self._pending: Dict[int, _Pending] = {}
        self._responses_seen = 0
        self._advance_reply: Optional[pb.Response] = None
        self._advance_id = 0
        self._advance_done = threading.Event()
        self._reader = threading.Thread(target=self._read_loop, name="canfleet-clock", daemon=True)
        self._reader.start()
        with _active_lock:
            if _active is not None and _active._closed is None:
                self._sock.close()
                raise CanfleetError("another driven fleet's clock is active in this process: one at a time")
            _active = self

    # -- time ----------------------------------------------------------------------------------
    @property
    def now(self) -> float:
        """Simulated seconds."""
        return self.now_ns / 1e9

    def deadline_ns(self, timeout: Optional[float]) -> Optional[int]:
        if timeout is None:
            return None
        return self.now_ns + max(0, round(timeout * 1e9))

    def sleep(self, seconds: float) -> None:
        """Waits `seconds` of simulated time (the fleet runs meanwhile)."""
        with self._cv:
            self.block(self.new_waiter(self.deadline_ns(seconds)))

    # -- waits (callers hold self._cv) ---------------------------------------------------------
    @property
    def lock(self) -> threading.Condition:
        return self._cv

    def new_waiter(self, deadline_ns: Optional[int]) -> _Waiter:
        return _Waiter(threading.current_thread(), deadline_ns)

    def wake(self, waiter: _Waiter) -> None:
        """Ends `waiter`'s wait (call with the lock held): its thread counts as running from now,
        so time stands still until it waits again."""
        if not waiter.woken:
            waiter.woken = True
            self._waiting.pop(waiter.thread, None)
            self._cv.notify_all()

    def block(self, waiter: _Waiter) -> bool:
        """Waits (lock held) until `waiter` is woken (True) or simulated time reaches its deadline
        (False). Runs the fleet when every participant waits."""
        me = waiter.thread
        self._participants.add(me)
        since = time.monotonic()
        try:
            while True:
                if waiter.woken:
                    return True
                if self._closed is not None:
                    raise CanfleetError(self._closed)
                if waiter.deadline_ns is not None and self.now_ns >= waiter.deadline_ns:
                    return False
                self._waiting[me] = waiter
                if not self._advancing and self._everyone_waits():
                    self._advance()
                    continue
                self._cv.wait(_POLL_S)
                if time.monotonic() - since > _STALL_S and not self._advancing:
                    since = time.monotonic()
                    running = sorted(t.name for t in self._participants if t not in self._waiting)
                    _log.warning("simulated time has stood still for %.0f s: thread(s) %s take part but are not "
                                 "in a simulated wait (blocked on something else?); see python/README.md "
                                 "\"Virtual time\"", _STALL_S, ", ".join(running))
        finally:
            self._waiting.pop(me, None)

    def _everyone_waits(self) -> bool:
        gone = [t for t in self._participants if not t.is_alive()]
        for t in gone:
            self._participants.discard(t)
            self._waiting.pop(t, None)
        return all(t in self._waiting for t in self._participants)

    def _advance(self) -> None:
        """Runs the fleet to the earliest deadline (lock held on entry and exit; released during
        the step). Wakes the waiters whose deadline it reached."""
        deadlines = [w.deadline_ns for w in self._waiting.values() if w.deadline_ns is not None]
        until = min(deadlines) if deadlines else self.now_ns + FOREVER_NS
        seen = self._responses_seen
        buses = list(self._buses)
        self._advancing = True
        self._cv.release()
        try:
            for bus in buses:  # the broker reads their frames before the step: they go on at now
                bus._sync()
            reply = self._step(until, seen)
            if reply.woken:
                for bus in buses:  # what the step delivered is in their inboxes before anyone looks
                    bus._sync()
        finally:
            self._cv.acquire()
            self._advancing = False
        self.advances += 1
        self.now_ns = max(self.now_ns, reply.now_ns)
        for w in list(self._waiting.values()):
            if w.deadline_ns is not None and w.deadline_ns <= self.now_ns:
                self._cv.notify_all()
                break

    def _step(self, until_ns: int, seen: int) -> pb.ClockState:
        request = pb.Request(clock_advance=pb.ClockAdvance(until_ns=until_ns, responses_seen=seen))
        self._advance_done.clear()
        self._advance_reply = None
        request.id = next(self._ids)
        self._advance_id = request.id
        self._send(request)
        while not self._advance_done.wait(_POLL_S):
            if self._closed is not None:
                raise CanfleetError(self._closed)
        response = self._advance_reply
        if response is None:
            raise CanfleetError(self._closed or "canfleet clock: no answer to ClockAdvance")
        if response.error:
            raise CanfleetError(f"ClockAdvance: {response.error}")
        return response.clock

    # -- control requests ----------------------------------------------------------------------
    def call(self, request: pb.Request) -> pb.Response:
        """Sends a control request and waits in simulated time for its answer (the fleet runs
        meanwhile, and stops where the answer came). Errors as ControlClient.call."""
        with self._cv:
            waiter = self.new_waiter(None)
            request.id = next(self._ids)
            pending = _Pending(waiter)
            self._pending[request.id] = pending
            self._cv.release()
            try:
                self._send(request)
            finally:
                self._cv.acquire()
            self.block(waiter)
        if pending.error is not None:
            raise pending.error
        response = pending.response
        assert response is not None
        if response.error:
            raise SdoAbortError.parse(response.error, request.WhichOneof("body") or "")
        return response

    def _send(self, request: pb.Request) -> None:
        try:
            with self._send_lock:
                self._sock.sendall(delimited(request.SerializeToString()))
        except OSError as e:
            self._fail(f"control connection to {self.control} failed: {e}")
            raise NotReachableError(f"control connection to {self.control} failed: {e}") from None

    def _read_loop(self) -> None:
        reader = DelimitedReader()
        reason = f"the orchestrator at {self.control} closed the connection"
        try:
            while True:
                data = self._sock.recv(65536)
                if not data:
                    break
                reader.feed(data)
                while (body := reader.next()) is not None:
                    response = pb.Response()
                    response.ParseFromString(body)
                    self._dispatch(response)
        except (OSError, FramingError) as e:
            reason = f"control connection to {self.control} failed: {e}"
        self._fail(reason)

    def _dispatch(self, response: pb.Response) -> None:
        with self._cv:
            self._responses_seen += 1
            if response.id == self._advance_id:
                self._advance_reply = response
                self._advance_done.set()
                return
            pending = self._pending.pop(response.id, None)
            if pending is None:
                return
            pending.response = response
            self.wake(pending.waiter)

    def _fail(self, reason: str) -> None:
        with self._cv:
            if self._closed is None:
                self._closed = f"canfleet clock: {reason}"
            for pending in self._pending.values():
                pending.error = NotReachableError(reason)
                self.wake(pending.waiter)
            self._pending.clear()
            self._advance_done.set()
            self._cv.notify_all()

    # -- buses and shutdown --------------------------------------------------------------------
    def add_bus(self, bus: Any) -> None:
        with self._cv:
            self._buses.append(bus)

    def remove_bus(self, bus: Any) -> None:
        with self._cv:
            if bus in self._buses:
                self._buses.remove(bus)

    def interrupt(self, threads: List[threading.Thread]) -> None:
        """Ends the waits of `threads` early (python-can's Notifier.stop: its reader thread leaves
        its recv at once, as a real bus's would within its poll); they no longer take part."""
        with self._cv:
            for t in threads:
                self._participants.discard(t)
                self._interrupted.add(t)
                w = self._waiting.get(t)
                if w is not None:
                    self.wake(w)
            self._cv.notify_all()

    def consume_interrupt(self) -> bool:
        """True once after interrupt() ended the calling thread's wait."""
        with self._cv:
            t = threading.current_thread()
            if t in self._interrupted:
                self._interrupted.discard(t)
                return True
            return False

    def join(self, thread: Optional[threading.Thread] = None) -> None:
        """Counts `thread` (default: the calling one) as a participant from now on: time stands
        still while it runs."""
        with self._cv:
            self._participants.add(thread or threading.current_thread())

    def leave(self, thread: Optional[threading.Thread] = None) -> None:
        """The thread no longer takes part (it ends, or only waits on things outside the fleet)."""
        with self._cv:
            self._participants.discard(thread or threading.current_thread())
            self._cv.notify_all()

    def close(self) -> None:
        global _active
        self._fail("the fleet is closed")
        try:
            self._sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._sock.close()
        with _active_lock:
            if _active is self:
                _active = None

