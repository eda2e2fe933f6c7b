"""Exceptions of the canfleet package. Every refusal of the orchestrator or the broker becomes one
of these, carrying the server's own one-line message (CONTRIBUTING.md: errors are data in the
protocol path, exceptions at the edges)."""
from __future__ import annotations

import re
from pathlib import Path
from typing import Optional


class CanfleetError(Exception):
    """Base class of everything this package raises on purpose."""


class NotReachableError(CanfleetError):
    """No orchestrator (control API) or broker answers at an endpoint."""


class OrchestratorError(CanfleetError):
    """The orchestrator refused a control request; `str(e)` is its message (Response.error)."""

    def __init__(self, message: str, request: str = "") -> None:
        super().__init__(message)
        self.message = message
        self.request = request


_SDO_ABORT = re.compile(r"SDO abort ([0-9A-Fa-f]{8})")


class SdoAbortError(OrchestratorError):
    """An SDO transfer of the orchestrator's SDO client ended with an abort; `code` is the CiA 301
    §7.2.4.3.17 abort code (0x06020000: object does not exist)."""

    def __init__(self, message: str, code: int, request: str = "") -> None:
        super().__init__(message, request)
        self.code = code

    @staticmethod
    def parse(message: str, request: str = "") -> OrchestratorError:
        """An SdoAbortError when `message` names an abort code, else an OrchestratorError."""
        m = _SDO_ABORT.search(message)
        if m is None:
            return OrchestratorError(message, request)
        return SdoAbortError(message, int(m.group(1), 16), request)


_LOCATED = re.compile(r"^(?P<file>.+?):(?P<line>\d+):(?P<column>\d+): (?P<rest>.*)$", re.S)


class TopologyError(CanfleetError):
    """The topology file was refused (by `canfleet check`, before anything started). `file`,
    `line` and `column` locate the refusal when the loader gave a place
    (`FILE:LINE:COL: FIELD: reason`, orchestrator/topology/located_error.hpp)."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message
        self.file: Optional[Path] = None
        self.line: Optional[int] = None
        self.column: Optional[int] = None
        self.reason = message
        m = _LOCATED.match(message.strip().splitlines()[0] if message.strip() else "")
        if m is not None:
            self.file = Path(m.group("file"))
            self.line = int(m.group("line"))
            self.column = int(m.group("column"))
            self.reason = m.group("rest")


class FleetStartError(CanfleetError):
    """The fleet did not start: `canfleet up` exited, a node exited before the fleet was ready, or
    it was not ready in time. The message ends with the orchestrator log's tail; `log` is its path."""

    def __init__(self, message: str, log: Optional[Path] = None) -> None:
        super().__init__(message)
        self.log = log


class NodeDiedError(CanfleetError):
    """A node process of the fleet ended while it should have run (not by a fault this fleet
    injected). `node` is its name, `detail` the orchestrator's description of its exit status
    ("exit code 3", "signal 11 (Segmentation fault)")."""

    def __init__(self, node: str, detail: str) -> None:
        super().__init__(f"node {node} died during the test: {detail}")
        self.node = node
        self.detail = detail


class WireVersionError(CanfleetError):
    """The broker speaks another version of the node wire protocol (bus/wire/canfleet_wire.proto)
    than this package was generated for."""

    def __init__(self, ours: int, theirs: int, endpoint: str, reason: str) -> None:
        super().__init__(
            f"node wire protocol mismatch with the broker at {endpoint}: this canfleet package speaks "
            f"version {ours}, the broker version {theirs} ({reason}). Install the package of the same "
            f"canfleet build as the broker (pip install ./python, or scripts/python-env.sh)")
        self.ours = ours
        self.theirs = theirs
        self.endpoint = endpoint


class BrokerRefusedError(CanfleetError):
    """The broker refused the participant's Hello (unknown bus, virtual time, bad bit rate...);
    `str(e)` carries the broker's reason."""
