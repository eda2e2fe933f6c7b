"""pytest plugin (entry point `pytest11`): a `fleet` fixture from a marker or an option, and what a
failing test's report carries.

    @pytest.mark.topology("topologies/pair.textproto")
    def test_quad(fleet):                 # a canfleet.Fleet, ready, stopped after the test
        fleet.node("quad-5").io_set("IN1.voltage_mV", 1800)

Options: --canfleet-topology FILE (for tests without the marker), --canfleet-time real|virtual,
--canfleet-seed N, --canfleet-bin DIR (canfleet and canfleet-node), --canfleet-keep (keep every
fleet's state folder). The marker's keyword arguments (time, seed, ready_timeout, log_level,
telemetry) override the options for its test.

On failure the test's report gets a "canfleet" section (the fleet's status, the orchestrator log's
path and tail, the captures) and its JUnit properties (--junitxml) the log, state and capture paths;
the state folder is then kept. A node process that died during the test (not by a process fault
the test injected) fails the test with its exit status (canfleet.NodeDiedError).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Dict, Generator, List, Optional

import pytest

from .errors import CanfleetError
from .fleet import Fleet, tail

_FLEETS = pytest.StashKey[List[Fleet]]()
_FAILED = pytest.StashKey[bool]()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("canfleet", "canfleet fleets (python/README.md)")
    group.addoption("--canfleet-topology", default=None, metavar="FILE",
                    help="topology of the `fleet` fixture for tests without @pytest.mark.topology")
    group.addoption("--canfleet-time", choices=("real", "virtual"), default="real",
                    help="time of the fleets the `fleet` fixture starts (default real)")
    group.addoption("--canfleet-seed", type=int, default=None, metavar="N",
                    help="seed of the faults that give none (default: the topology's time.seed)")
    group.addoption("--canfleet-bin", default=None, metavar="DIR",
                    help="folder of canfleet and canfleet-node (default $CANFLEET_BIN_DIR, PATH, build/bin)")
    group.addoption("--canfleet-keep", action="store_true",
                    help="keep every fleet's state folder (logs, captures), not only failed tests'")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "topology(path, **options): the `fleet` fixture starts this topology (relative to the test "
        "file's folder, else the current folder); options: time, seed, ready_timeout, log_level, telemetry")


def _topology_path(item: pytest.Item, given: str) -> Path:
    path = Path(given)
    if path.is_absolute():
        return path
    beside = Path(str(item.path)).parent / path
    return beside if beside.exists() else Path.cwd() / path


@pytest.fixture
def fleet(request: pytest.FixtureRequest) -> Generator[Fleet, None, None]:
    """A running canfleet.Fleet of the test's topology (@pytest.mark.topology or
    --canfleet-topology), stopped after the test with every process."""
    config = request.config
    marker = request.node.get_closest_marker("topology")
    options: Dict[str, Any] = {"time": config.getoption("--canfleet-time"),
                               "seed": config.getoption("--canfleet-seed"),
                               "bin_dir": config.getoption("--canfleet-bin")}
    if marker is not None:
        if len(marker.args) != 1:
            raise pytest.UsageError(f"{request.node.nodeid}: @pytest.mark.topology takes one path")
        topology = _topology_path(request.node, str(marker.args[0]))
        options.update(marker.kwargs)
    elif config.getoption("--canfleet-topology"):
        topology = Path(config.getoption("--canfleet-topology"))
    else:
        raise pytest.UsageError(f"{request.node.nodeid}: the fleet fixture needs @pytest.mark.topology(...) "
                                "or --canfleet-topology")
    started = Fleet.up(topology, **options)
    request.node.stash.setdefault(_FLEETS, []).append(started)
    try:
        yield started
    finally:
        keep = config.getoption("--canfleet-keep") or request.node.stash.get(_FAILED, False)
        if keep:
            started.remove_state_at_close = False
        started.close()


@pytest.fixture
def canfleet_bus(fleet: Fleet) -> Generator[Callable[..., Any], None, None]:
    """canfleet_bus(channel="can0", **options) -> a python-can Bus on `fleet` (interface
    "canfleet"), shut down after the test."""
    import can

    buses: List[can.BusABC] = []

    def make(channel: str = "can0", **options: Any) -> can.BusABC:
        bus = can.Bus(interface="canfleet", channel=channel, fleet=fleet, **options)
        buses.append(bus)
        return bus

    yield make
    for bus in buses:
        bus.shutdown()


def _report(fleet: Fleet) -> str:
    lines: List[str] = []
    try:
        lines.append(fleet.status_text())
    except CanfleetError as e:
        lines.append(f"(no status: {e})")
    lines.append(f"orchestrator log: {fleet.log_path}")
    lines.append(f"state folder: {fleet.state_dir}")
    for capture in fleet.captures:
        lines.append(f"capture {capture.id} of {capture.bus}: {capture.path}")
    if fleet.log_path is not None:
        lines.append(f"--- orchestrator log, last lines ---\n{tail(fleet.log_path, 30)}")
    return "\n".join(lines)


def _note_failure(item: pytest.Item, fleets: List[Fleet]) -> None:
    item.stash[_FAILED] = True
    for i, f in enumerate(fleets):
        if f.closed:
            continue
        item.add_report_section("call", "canfleet" if i == 0 else f"canfleet {i + 1}", _report(f))
        item.user_properties.append(("canfleet_log", str(f.log_path)))
        item.user_properties.append(("canfleet_state", str(f.state_dir)))
        for capture in f.captures:
            item.user_properties.append((f"canfleet_capture_{capture.id}", str(capture.path)))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item) -> Generator[None, Optional[object], Optional[object]]:
    fleets = item.stash.get(_FLEETS, [])
    try:
        result = yield
    except BaseException:
        _note_failure(item, fleets)
        raise
    for f in fleets:
        if f.closed:
            continue
        dead = f.dead_nodes()
        if dead:
            _note_failure(item, fleets)
            raise dead[0]
    return result
