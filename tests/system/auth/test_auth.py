"""The fleet's token (issue 32; bus/wire/auth_token.hpp, docs in orchestrator/README.md "Who may
connect"): an orchestrator whose control API and broker listen on 0.0.0.0 lets in only clients
that send the token, and tells the others why; one on loopback needs none. Real processes: the
orchestrator, its node processes (which get the token from CANFLEET_TOKEN_FILE), the CLI, the
Python control client, python-can's canfleet interface, an external canfleet-node."""
from __future__ import annotations

import json
import os
import socket
import subprocess
import time
from pathlib import Path
from typing import Dict, Generator, List, Optional

import can
import pytest

from canfleet import auth
from canfleet.control import ControlClient
from canfleet.errors import BrokerRefusedError, OrchestratorError
from canfleet.fleet import find_binaries
from canfleet._proto import control as pb

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
PAIR = REPO / "python" / "tests" / "topologies" / "pair.textproto"
TOKEN = "fleet-token-for-the-auth-test-0123"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def clean_env(**extra: str) -> Dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("CANFLEET_TOKEN", "CANFLEET_TOKEN_FILE")}
    env.update(extra)
    return env


def write_token(folder: Path, name: str, token: str) -> Path:
    path = folder / name
    path.write_text(token + "\n")
    return path


class OpenFleet:
    """`canfleet up` with its control API and broker on 0.0.0.0 (reached here through 127.0.0.1)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.token_file = write_token(folder, "token", TOKEN)
        self.control = f"tcp://127.0.0.1:{free_port()}"
        self.broker_port = free_port()
        self.broker = f"tcp://127.0.0.1:{self.broker_port}"
        self.log = folder / "up.log"
        ready = folder / "ready"
        self.proc = subprocess.Popen(
            [str(find_binaries() / "canfleet"), "up", str(PAIR), "--no-telemetry",
             "--control", self.control.replace("127.0.0.1", "0.0.0.0"),
             "--listen", f"tcp://0.0.0.0:{self.broker_port}",
             "--ready-file", str(ready), "--state-dir", str(folder / "nodes")],
            stdout=open(self.log, "wb"), stderr=subprocess.STDOUT,
            env=clean_env(CANFLEET_TOKEN_FILE=str(self.token_file)))
        end = time.monotonic() + 60
        while "state ready" not in (ready.read_text() if ready.exists() else ""):
            if self.proc.poll() is not None or time.monotonic() > end:
                self.stop()
                raise RuntimeError(f"canfleet up did not get ready:\n{self.log.read_text()[-3000:]}")
            time.sleep(0.1)

    def cli(self, *args: str, token_file: Optional[Path] = None) -> subprocess.CompletedProcess[str]:
        env = clean_env(**({"CANFLEET_TOKEN_FILE": str(token_file)} if token_file else {}))
        return subprocess.run([str(find_binaries() / "canfleet"), "--control", self.control, "--timeout", "10s",
                               *args], capture_output=True, text=True, env=env, timeout=60)

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(timeout=60)


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> Generator[OpenFleet, None, None]:
    f = OpenFleet(tmp_path_factory.mktemp("auth"))
    yield f
    f.stop()
    assert f.proc.returncode == 0, f.log.read_text()[-3000:]


def test_the_nodes_joined_the_broker_beyond_loopback_with_the_token(fleet: OpenFleet) -> None:
    # The orchestrator started them with CANFLEET_TOKEN_FILE in their environment.
    end = time.monotonic() + 30
    while True:
        out = fleet.cli("status", "--json", token_file=fleet.token_file)
        assert out.returncode == 0, out.stderr
        nodes = {n["name"]: n for n in json.loads(out.stdout)["nodes"]}
        if all(nodes[q].get("nmt_state") == "operational" for q in ("quad-5", "quad-6")):
            break
        assert time.monotonic() < end, out.stdout
        time.sleep(0.2)
    assert all(n.get("attached") for n in nodes.values())


def test_the_cli_without_a_token_is_refused_and_told_why(fleet: OpenFleet) -> None:
    out = fleet.cli("status")
    assert out.returncode != 0
    assert "refused: no token" in out.stderr, out.stderr


def test_the_cli_with_a_wrong_token_is_refused(fleet: OpenFleet, tmp_path: Path) -> None:
    out = fleet.cli("nmt", "stop", token_file=write_token(tmp_path, "wrong", "not-the-fleet-token-000000"))
    assert out.returncode != 0
    assert "refused: wrong token" in out.stderr, out.stderr
    # nothing happened: the nodes are still operational
    status = json.loads(fleet.cli("status", "--json", token_file=fleet.token_file).stdout)
    assert {n["name"]: n.get("nmt_state") for n in status["nodes"] if n["name"] != "io-21"} == \
        {"quad-5": "operational", "quad-6": "operational"}


def test_refusals_are_logged_with_the_peer(fleet: OpenFleet) -> None:
    fleet.cli("status")
    log = fleet.log.read_text()
    assert "control API: refused 127.0.0.1:" in log
    assert "no token" in log and "wrong token" in log


def test_the_python_client_needs_the_token_too(fleet: OpenFleet) -> None:
    with ControlClient(fleet.control, timeout=10, token=None) as anonymous:
        os.environ.pop("CANFLEET_TOKEN", None)
        os.environ.pop("CANFLEET_TOKEN_FILE", None)
        with pytest.raises(OrchestratorError, match="refused: no token"):
            anonymous.call(pb.Request(status=pb.StatusRequest()))
    with ControlClient(fleet.control, timeout=10, token=TOKEN) as client:
        assert len(client.call(pb.Request(status=pb.StatusRequest())).status.nodes) == 3


def test_python_can_joins_the_bus_only_with_the_token(fleet: OpenFleet) -> None:
    with pytest.raises(BrokerRefusedError, match="refused .* on can0: no token"):
        can.Bus(interface="canfleet", channel="can0", broker=fleet.broker, token=None)
    with can.Bus(interface="canfleet", channel="can0", broker=fleet.broker, token=TOKEN) as bus:
        # quad-5's heartbeat (701h + ... : 705h) every 100 ms
        end = time.monotonic() + 10
        seen = False
        while not seen and time.monotonic() < end:
            msg = bus.recv(1.0)
            seen = msg is not None and msg.arbitration_id == 0x705
        assert seen


def test_an_external_node_without_the_token_never_attaches(fleet: OpenFleet, tmp_path: Path) -> None:
    log = tmp_path / "node.log"
    node = subprocess.Popen([str(find_binaries() / "canfleet-node"), "--device", "quad-controller", "--node-id", "40",
                             "--name", "intruder", "--bus", f"can0@{fleet.broker}", "--no-telemetry"],
                            stdout=open(log, "wb"), stderr=subprocess.STDOUT, env=clean_env())
    try:
        end = time.monotonic() + 20
        while "refused: no token" not in log.read_text() and time.monotonic() < end:
            time.sleep(0.1)
        assert "refused: no token" in log.read_text(), log.read_text()
        assert "intruder" not in fleet.cli("status", token_file=fleet.token_file).stdout
    finally:
        node.kill()
        node.wait()


def test_garbage_and_silent_clients_are_refused_and_the_fleet_carries_on(fleet: OpenFleet) -> None:
    port = int(fleet.control.rsplit(":", 1)[1])
    silent: List[socket.socket] = [socket.create_connection(("127.0.0.1", port)) for _ in range(20)]
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(os.urandom(4096))
        reply = b""
        while True:
            chunk = s.recv(4096)
            if not chunk:
                break
            reply += chunk
        assert b"refused: no token" in reply
    with socket.create_connection(("127.0.0.1", fleet.broker_port), timeout=10) as s:
        s.sendall(auth.MAGIC + bytes([200]) + b"x" * 10)  # a preamble that never finishes
        s.sendall(b"y" * 190)
        s.sendall(b"z" * 10)
        assert b"wrong token" in s.recv(4096)
    out = fleet.cli("status", token_file=fleet.token_file)
    assert out.returncode == 0, out.stderr
    for s in silent:
        s.close()


def test_up_beyond_loopback_without_a_token_does_not_start(tmp_path: Path) -> None:
    out = subprocess.run([str(find_binaries() / "canfleet"), "up", str(PAIR), "--no-telemetry", "--no-start",
                          "--control", f"tcp://0.0.0.0:{free_port()}", "--listen", f"unix://{tmp_path / 'b.sock'}",
                          "--state-dir", str(tmp_path / "nodes")],
                         capture_output=True, text=True, env=clean_env(), timeout=60)
    assert out.returncode == 2
    assert "needs the fleet's token" in out.stdout + out.stderr


def test_on_loopback_no_token_is_needed(tmp_path: Path) -> None:
    control = f"tcp://127.0.0.1:{free_port()}"
    ready = tmp_path / "ready"
    up = subprocess.Popen([str(find_binaries() / "canfleet"), "up", str(PAIR), "--no-telemetry", "--no-start",
                           "--control", control, "--listen", f"unix://{tmp_path / 'b.sock'}",
                           "--ready-file", str(ready), "--state-dir", str(tmp_path / "nodes")],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=clean_env())
    try:
        end = time.monotonic() + 30
        while not ready.exists() and time.monotonic() < end:
            time.sleep(0.1)
        out = subprocess.run([str(find_binaries() / "canfleet"), "--control", control, "status"],
                             capture_output=True, text=True, env=clean_env(), timeout=60)
        assert out.returncode == 0, out.stderr
    finally:
        up.terminate()
        up.wait(timeout=60)


def _listening_socket_inodes(port: int) -> set[str]:
    inodes = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as f:
            next(f)
            for line in f:
                fields = line.split()
                if fields[3] == "0A" and int(fields[1].rsplit(":", 1)[1], 16) == port:  # 0A: LISTEN
                    inodes.add(fields[9])
    return inodes


def test_node_processes_hold_none_of_the_orchestrators_sockets(fleet: OpenFleet) -> None:
    # Issue 32: a hung node must not keep the fleet's ports bound. The node processes' descriptors
    # are compared with the orchestrator's listening sockets (control API and broker).
    listeners = _listening_socket_inodes(int(fleet.control.rsplit(":", 1)[1])) | \
        _listening_socket_inodes(fleet.broker_port)
    assert listeners, "the orchestrator's listening sockets were not found in /proc/net"
    status = json.loads(fleet.cli("status", "--json", token_file=fleet.token_file).stdout)
    pids = [n["pid"] for n in status["nodes"] if n.get("pid")]
    assert len(pids) == 3
    for pid in pids:
        held = set()
        for fd in os.listdir(f"/proc/{pid}/fd"):
            target = os.readlink(f"/proc/{pid}/fd/{fd}")
            if target.startswith("socket:["):
                held.add(target[len("socket:["):-1])
        assert not held & listeners, f"node process {pid} holds the orchestrator's listening sockets"
        # and nothing beyond its own few: stdio, its broker connection, its DDS sockets, its log
        assert len(os.listdir(f"/proc/{pid}/fd")) < 40
