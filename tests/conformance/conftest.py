"""pytest wiring: `--build-dir` (the binaries under test), the session's fleet, and one fresh node
per test, parametrised over variants.VARIANTS."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

from harness import Fleet, NodeUnderTest, tail
from variants import REPO, VARIANTS


def pytest_addoption(parser):
    parser.addoption("--build-dir", default=os.environ.get("CANFLEET_BUILD_DIR", str(REPO / "build")),
                     help="CMake build folder whose bin/ holds canfleet and canfleet-node")


@pytest.fixture(scope="session")
def bin_dir(request) -> Path:
    path = Path(request.config.getoption("--build-dir")).resolve() / "bin"
    for tool in ("canfleet", "canfleet-node"):
        if not os.access(path / tool, os.X_OK):
            pytest.exit(f"{path / tool} is missing: build it first (or pass --build-dir)", returncode=2)
    return path


@pytest.fixture(scope="session")
def fleet(bin_dir, tmp_path_factory, request):
    f = Fleet(bin_dir, tmp_path_factory.mktemp("fleet"), VARIANTS, request.config.getoption("--canfleet-time"))
    yield f
    f.stop()


@pytest.fixture(params=VARIANTS, ids=[v.id for v in VARIANTS])
def variant(request):
    return request.param


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    setattr(item, "rep_" + report.when, report)


@pytest.fixture
def start_node(fleet, variant, tmp_path, request):
    """start_node(extra_args=None) -> a running NodeUnderTest after its boot-up. Its process log
    is printed when the test fails."""
    nodes = []

    def start(extra_args=None, start_process=True):
        node = NodeUnderTest(fleet, variant, tmp_path / f"node{len(nodes)}", extra_args)
        nodes.append(node)
        if start_process:
            node.start()
        return node

    yield start
    failed = getattr(request.node, "rep_call", None) is not None and request.node.rep_call.failed
    for node in nodes:
        code = node.close()
        if failed:
            print(f"\n--- {variant.name} log ({node.log}) ---\n{tail(node.log, 60)}")
        # A node process must end cleanly on SIGTERM: a crash is a bug whatever the test checked.
        assert code in (None, 0), f"{variant.name} exited with {code} on SIGTERM:\n{tail(node.log)}"
    if failed:
        print(f"\n--- orchestrator log ---\n{tail(fleet.log, 30)}")


@pytest.fixture
def node(start_node):
    return start_node()
