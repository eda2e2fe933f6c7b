"""Starting the orchestrator so that it never outlives the Python process that started it.

`canfleet up` is started with PR_SET_PDEATHSIG = SIGTERM (prctl(2)): when the process that started
it dies - Ctrl-C, an exception, or SIGKILL of the test process, where no Python code runs - the
kernel sends it SIGTERM, and it stops its node processes as on Ctrl-C (they in turn carry
PR_SET_PDEATHSIG from the orchestrator, orchestrator/fleet/child_process.cpp, should it die first).

The death signal is tied to the *thread* that forked, not the process (prctl(2): "the parent thread
terminates"). So the fork happens on one long-lived spawner thread of this module, never on the
caller's thread: a fleet started from a worker thread that ends keeps running until the process
ends.
"""
from __future__ import annotations

import ctypes
import os
import queue
import signal
import subprocess
import threading
from typing import Any, Callable, List, Optional

_PR_SET_PDEATHSIG = 1


def _die_with_parent(parent: int) -> Callable[[], None]:
    def preexec() -> None:  # runs in the child between fork and exec
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        if os.getppid() != parent:  # the parent died before prctl: nobody would stop us
            os._exit(1)
    return preexec


class _Spawner:
    """One daemon thread that lives as long as the process and does every fork."""

    def __init__(self) -> None:
        self._jobs: "queue.Queue[tuple[Callable[[], Any], queue.Queue[Any]]]" = queue.Queue()
        self._thread: Optional[threading.Thread] = None
        self._lock = threading.Lock()

    def run(self, job: Callable[[], Any]) -> Any:
        with self._lock:
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(target=self._loop, name="canfleet-spawner", daemon=True)
                self._thread.start()
        done: "queue.Queue[Any]" = queue.Queue(maxsize=1)
        self._jobs.put((job, done))
        ok, value = done.get()
        if not ok:
            raise value
        return value

    def _loop(self) -> None:
        while True:
            job, done = self._jobs.get()
            try:
                done.put((True, job()))
            except BaseException as e:  # noqa: BLE001 - handed to the caller
                done.put((False, e))


_spawner = _Spawner()


def spawn_tied(args: List[str], **popen: Any) -> "subprocess.Popen[bytes]":
    """subprocess.Popen(args, **popen) in a new session, SIGTERMed by the kernel when this process
    dies."""
    parent = os.getpid()
    proc: "subprocess.Popen[bytes]" = _spawner.run(lambda: subprocess.Popen(
        args, start_new_session=True, preexec_fn=_die_with_parent(parent), **popen))
    return proc
