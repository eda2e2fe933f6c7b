"""Simulated-time versions of the waiting primitives, for python-can and python-canopen on a driven
fleet (python/README.md, "Virtual time"). With no clock active (real time) each behaves exactly
as the standard library's.

- SimCondition: threading.Condition whose wait() waits in simulated time.
- SimQueue: queue.Queue whose get(timeout) waits in simulated time.
- install(): points python-canopen's modules at them (its SDO, LSS, NMT, EMCY and PDO waits, its
  time.time() and time.sleep()), and makes python-can's Notifier.stop() end its reader's wait at
  once. Done when a driven fleet's clock starts; objects python-canopen made before keep the
  standard primitives: adopt(network) swaps those of a Network and its nodes.
"""
from __future__ import annotations

import queue as _queue
import threading
import time as _time
import types
from typing import Any, Callable, List, Optional

from .clock import Clock, active


class SimCondition(threading.Condition):
    """threading.Condition; wait() and wait_for() count simulated seconds while a clock is active."""

    def __init__(self, lock: Any = None) -> None:
        super().__init__(lock)
        self._sim_waiters: List[Any] = []

    def wait(self, timeout: Optional[float] = None) -> bool:
        clock = active()
        if clock is None:
            return super().wait(timeout)
        if not self._is_owned():  # type: ignore[attr-defined]
            raise RuntimeError("cannot wait on un-acquired lock")
        with clock.lock:
            waiter = clock.new_waiter(clock.deadline_ns(timeout))
            self._sim_waiters.append(waiter)
        saved = self._release_save()  # type: ignore[attr-defined]
        try:
            with clock.lock:
                return clock.block(waiter)
        finally:
            self._acquire_restore(saved)  # type: ignore[attr-defined]
            with clock.lock:
                if waiter in self._sim_waiters:
                    self._sim_waiters.remove(waiter)

    def wait_for(self, predicate: Callable[[], Any], timeout: Optional[float] = None) -> Any:
        clock = active()
        if clock is None:
            return super().wait_for(predicate, timeout)
        deadline = clock.deadline_ns(timeout)
        result = predicate()
        while not result:
            if deadline is None:
                self.wait(None)
            else:
                left = deadline - clock.now_ns
                if left <= 0:
                    break
                self.wait(left / 1e9)
            result = predicate()
        return result

    def notify(self, n: int = 1) -> None:
        clock = active()
        if clock is not None and self._sim_waiters:
            with clock.lock:
                woken = 0
                while self._sim_waiters and woken < n:
                    clock.wake(self._sim_waiters.pop(0))
                    woken += 1
        super().notify(n)

    def notify_all(self) -> None:
        self.notify(len(self._sim_waiters) + len(self._waiters))  # type: ignore[attr-defined]

    notifyAll = notify_all


class SimQueue(_queue.Queue):  # type: ignore[type-arg]
    """queue.Queue whose blocking get(timeout) waits in simulated time while a clock is active."""

    def __init__(self, maxsize: int = 0) -> None:
        super().__init__(maxsize)
        self.not_empty = SimCondition(self.mutex)
        self.not_full = SimCondition(self.mutex)
        self.all_tasks_done = SimCondition(self.mutex)

    def get(self, block: bool = True, timeout: Optional[float] = None) -> Any:
        if active() is None or not block:
            return super().get(block, timeout)
        with self.not_empty:
            if not self.not_empty.wait_for(self._qsize, timeout):
                raise _queue.Empty
            item = self._get()
            self.not_full.notify()
            return item


class _TimeShim(types.ModuleType):
    """The `time` module as python-canopen's modules see it: simulated time() and sleep()."""

    def __init__(self) -> None:
        super().__init__("time")

    @staticmethod
    def time() -> float:
        clock = active()
        return clock.now if clock is not None else _time.time()

    @staticmethod
    def sleep(seconds: float) -> None:
        clock = active()
        if clock is None:
            _time.sleep(seconds)
        else:
            clock.sleep(seconds)

    def __getattr__(self, name: str) -> Any:
        return getattr(_time, name)


class _ThreadingShim(types.ModuleType):
    Condition = SimCondition

    def __init__(self) -> None:
        super().__init__("threading")

    def __getattr__(self, name: str) -> Any:
        return getattr(threading, name)


class _QueueShim(types.ModuleType):
    Queue = SimQueue
    Empty = _queue.Empty
    Full = _queue.Full

    def __init__(self) -> None:
        super().__init__("queue")

    def __getattr__(self, name: str) -> Any:
        return getattr(_queue, name)


_SHIMS = {"time": _TimeShim(), "threading": _ThreadingShim(), "queue": _QueueShim()}
#: python-canopen's modules whose waits move to simulated time.
CANOPEN_MODULES = ("canopen.sdo.client", "canopen.lss", "canopen.nmt", "canopen.emcy", "canopen.pdo.base")
_installed = False


def install() -> None:
    """Points python-canopen (when installed) and python-can's Notifier at the simulated-time
    primitives; harmless in real time (they then behave as the standard ones). Idempotent."""
    global _installed
    if _installed:
        return
    _installed = True
    import importlib

    for name in CANOPEN_MODULES:
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        for attr, shim in _SHIMS.items():
            if getattr(module, attr, None) is {"time": _time, "threading": threading, "queue": _queue}[attr]:
                setattr(module, attr, shim)
    import can

    original_stop = can.Notifier.stop

    def stop(self: Any, timeout: float = 5) -> None:
        clock = active()
        self._running = False
        if clock is not None:
            clock.interrupt([r for r in getattr(self, "_readers", []) if isinstance(r, threading.Thread)])
        original_stop(self, timeout)

    can.Notifier.stop = stop  # type: ignore[method-assign]


def adopt(network: Any) -> None:
    """Swaps the waiting primitives of a python-canopen Network made before install() (its nodes'
    SDO clients, NMT, EMCY, PDO maps, its LSS master) for simulated-time ones."""
    install()
    for node in list(getattr(network, "nodes", {}).values()):
        sdo = getattr(node, "sdo", None)
        if sdo is not None and not isinstance(getattr(sdo, "responses", None), SimQueue):
            sdo.responses = SimQueue()
        nmt = getattr(node, "nmt", None)
        if nmt is not None and not isinstance(getattr(nmt, "state_update", None), SimCondition):
            nmt.state_update = SimCondition()
        emcy = getattr(node, "emcy", None)
        if emcy is not None and not isinstance(getattr(emcy, "emcy_received", None), SimCondition):
            emcy.emcy_received = SimCondition()
        for pdo in (getattr(node, "tpdo", None), getattr(node, "rpdo", None)):
            for m in (getattr(pdo, "map", None) or {}).values():
                if not isinstance(getattr(m, "receive_condition", None), SimCondition):
                    m.receive_condition = SimCondition()
    lss = getattr(network, "lss", None)
    if lss is not None and not isinstance(getattr(lss, "responses", None), SimQueue):
        lss.responses = SimQueue()


__all__ = ["SimCondition", "SimQueue", "install", "adopt", "Clock", "active"]
