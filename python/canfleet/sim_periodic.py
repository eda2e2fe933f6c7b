"""python-can periodic sending on a driven fleet's simulated clock: each task is a thread that sends
its messages and sleeps `period` simulated seconds, so a 20 ms cycle is 20 ms on the bus's time line
(python-can's own task sleeps in real time). python-canopen's heartbeat producer, SYNC and
Network.send_periodic come through here (CanfleetBus._send_periodic_internal)."""
from __future__ import annotations

import threading
from typing import Any, Callable, Optional, Sequence, Union

import can
from can.broadcastmanager import LimitedDurationCyclicSendTaskABC, ModifiableCyclicTaskABC, RestartableCyclicTaskABC

from .clock import Clock


class SimCyclicSendTask(LimitedDurationCyclicSendTaskABC, ModifiableCyclicTaskABC, RestartableCyclicTaskABC):
    def __init__(self, bus: Any, clock: Clock, messages: Union[Sequence[can.Message], can.Message], period: float,
                 duration: Optional[float] = None, autostart: bool = True,
                 modifier_callback: Optional[Callable[[can.Message], None]] = None) -> None:
        super().__init__(messages, period, duration)
        if period <= 0:
            raise ValueError(f"period {period!r}: positive seconds")
        self.bus = bus
        self.clock = clock
        self.modifier_callback = modifier_callback
        self._stopped = True
        self._thread: Optional[threading.Thread] = None
        if autostart:
            self.start()

    def start(self) -> None:
        if not self._stopped:
            return
        self._stopped = False
        self.end_time = None if self.duration is None else self.clock.now + self.duration
        self._thread = threading.Thread(target=self._run, name=f"canfleet-cyclic-{self.arbitration_id:X}",
                                        daemon=True)
        self.clock.join(self._thread)  # takes part from now: time waits for its first send
        self._thread.start()

    def stop(self) -> None:
        self._stopped = True
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            self.clock.interrupt([thread])

    def _run(self) -> None:
        index = 0
        try:
            while not self._stopped:
                if self.end_time is not None and self.clock.now >= self.end_time:
                    break
                msg = self.messages[index]
                if self.modifier_callback is not None:
                    self.modifier_callback(msg)
                try:
                    self.bus.send(msg)
                except can.CanError:
                    pass  # bus-off or shut down: a real controller's cyclic send keeps its rhythm
                index = (index + 1) % len(self.messages)
                self.clock.sleep(self.period)
                if self.clock.consume_interrupt():
                    break
        except Exception:  # the clock closed: the fleet is gone
            pass
        finally:
            self.clock.leave()
