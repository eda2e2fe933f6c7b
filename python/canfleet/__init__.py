"""canfleet from Python: fleet control over the orchestrator's control API (Fleet, Node, Fault),
a python-can interface joining a fleet bus through the node wire protocol
(`can.Bus(interface="canfleet", channel="can0")`, canfleet.can_bus), virtual time driven by the test
(canfleet.clock, canfleet.virtual), and a pytest plugin (canfleet.pytest_plugin). python/README.md has the whole API."""
from __future__ import annotations

from ._proto import WIRE_PROTOCOL_VERSION
from .errors import (BrokerRefusedError, CanfleetError, FleetStartError, NodeDiedError, NotReachableError,
                     OrchestratorError, SdoAbortError, TopologyError, WireVersionError)
from . import clock, virtual
from .fleet import Capture, Expectation, ExpectationFailed, Fault, Fleet, IoValue, Node, current, fault_spec

__version__ = "0.1.0"

__all__ = [
    "BrokerRefusedError", "CanfleetError", "Capture", "Expectation", "ExpectationFailed", "Fault", "Fleet", "FleetStartError", "IoValue", "Node",
    "NodeDiedError", "NotReachableError", "OrchestratorError", "SdoAbortError", "TopologyError",
    "WIRE_PROTOCOL_VERSION", "WireVersionError", "current", "fault_spec",
]
