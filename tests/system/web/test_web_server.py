"""`canfleet web` as a server (issue 31, "Security"): loopback by default; beyond loopback actions
need the token printed at start; garbage, huge requests, slow clients and more connections than it
takes get a clean refusal, and the server goes on serving (checked after each)."""
from __future__ import annotations

import http.client
import json
import os
import socket
import time
from pathlib import Path
from typing import Dict, List, Tuple
from urllib.parse import urlparse

import pytest

from canfleet import Fleet
from conftest import PAIR, start_web, up_with_web


def host_port(url: str) -> Tuple[str, int]:
    u = urlparse(url)
    return u.hostname or "127.0.0.1", int(u.port or 80)


def get(url: str, path: str) -> Tuple[int, bytes]:
    host, port = host_port(url)
    c = http.client.HTTPConnection(host, port, timeout=10)
    c.request("GET", path)
    r = c.getresponse()
    return r.status, r.read()


def post(url: str, body: object, token: str = "") -> Tuple[int, Dict[str, object]]:
    host, port = host_port(url)
    c = http.client.HTTPConnection(host, port, timeout=30)
    headers = {"Content-Type": "application/json"}
    if token:
        headers["Authorization"] = "Bearer " + token
    c.request("POST", "/api/action", body=json.dumps(body), headers=headers)
    r = c.getresponse()
    return r.status, json.loads(r.read())


def alive(url: str) -> bool:
    status, body = get(url, "/api/info")
    return status == 200 and b"actions" in body


def test_loopback_serves_the_page_state_and_actions_without_a_token(fleet: Fleet, webs: List[Dict[str, object]],
                                                                     tmp_path: Path) -> None:
    web = start_web("--listen", "127.0.0.1:0", control=fleet.control, folder=tmp_path)
    webs.append(web)
    url = str(web["url"])
    assert "#token" not in url and web["token"] == ""
    status, page = get(url, "/")
    assert status == 200 and b"<title>canfleet</title>" in page
    assert get(url, "/app.js")[0] == 200
    assert get(url, "/../CMakeLists.txt")[0] == 404  # only the page's own files
    assert get(url, "/nothing.js")[0] == 404
    status, body = post(url, {"status": {}})
    assert status == 200 and body["ok"] is True
    status, body = post(url, {"fault_inject": {"kind": "HEARTBEAT_LOSS", "node": "quad-9"}})
    assert status == 200 and body["ok"] is False and "quad-9" in str(body["error"])  # the orchestrator's words
    status, body = post(url, {"shutdown": {}})
    assert status == 400 and "not an action" in str(body["error"])  # the page may not stop the fleet
    status, body = post(url, "not json")
    assert status == 400


def test_beyond_loopback_actions_need_the_token(fleet: Fleet, webs: List[Dict[str, object]], tmp_path: Path) -> None:
    web = start_web("--listen", "0.0.0.0:0", control=fleet.control, folder=tmp_path)
    webs.append(web)
    url, token = str(web["url"]), str(web["token"])
    assert len(token) == 32 and url.endswith("#token=" + token)
    assert alive(url)  # reading needs no token
    assert post(url, {"status": {}})[0] == 403
    assert post(url, {"status": {}}, token="wrong")[0] == 403
    status, body = post(url, {"status": {}}, token=token)
    assert status == 200 and body["ok"] is True


def test_garbage_huge_and_slow_requests_are_refused_and_the_server_goes_on(
        fleet: Fleet, webs: List[Dict[str, object]], tmp_path: Path) -> None:
    web = start_web("--listen", "127.0.0.1:0", control=fleet.control, folder=tmp_path)
    webs.append(web)
    url = str(web["url"])
    host, port = host_port(url)
    # Random bytes: 400 and closed.
    with socket.create_connection((host, port), timeout=10) as s:
        s.sendall(os.urandom(4096) + b"\r\n\r\n")
        assert s.recv(100).startswith(b"HTTP/1.1 400")
    assert alive(url)
    # A header of 100 KiB and a body of 1 MiB: refused for their size.
    with socket.create_connection((host, port), timeout=10) as s:
        s.sendall(b"GET / HTTP/1.1\r\nHost: x\r\nX-Big: " + b"a" * 100_000 + b"\r\n\r\n")
        assert s.recv(100).split(b" ")[1] in (b"400", b"413", b"431")
    with socket.create_connection((host, port), timeout=10) as s:
        s.sendall(b"POST /api/action HTTP/1.1\r\nHost: x\r\nContent-Length: 1048576\r\n\r\n" + b"{" * 70_000)
        assert s.recv(100).split(b" ")[1] == b"413"
    assert alive(url)
    # A WebSocket message over 4 KiB from the page ends its session; the server goes on.
    with socket.create_connection((host, port), timeout=10) as s:
        s.sendall(b"GET /ws HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                  b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n")
        assert s.recv(12) == b"HTTP/1.1 101"
        payload = os.urandom(65536)
        mask = b"\x01\x02\x03\x04"
        s.sendall(bytes([0x82, 0xFF]) + len(payload).to_bytes(8, "big") + mask +
                  bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))
        s.settimeout(10)
        got = b""
        try:
            while chunk := s.recv(65536):
                got += chunk
        except (ConnectionResetError, socket.timeout):
            pass
    assert alive(url)
    # A slow client that never finishes its request does not hold up the others.
    slow = socket.create_connection((host, port), timeout=10)
    slow.sendall(b"GET / HTTP/1.1\r\n")
    assert alive(url)
    slow.close()


def test_more_connections_than_it_takes_are_answered_503(fleet: Fleet, webs: List[Dict[str, object]],
                                                         tmp_path: Path) -> None:
    web = start_web("--listen", "127.0.0.1:0", control=fleet.control, folder=tmp_path)
    webs.append(web)
    url = str(web["url"])
    host, port = host_port(url)
    held = []
    try:
        for _ in range(300):  # the server takes 256 at once
            held.append(socket.create_connection((host, port), timeout=10))
        time.sleep(0.5)  # let it accept them all (nothing is asserted on how soon)
        refused = 0
        for s in held[256:]:
            s.settimeout(5)
            try:
                if s.recv(100).startswith(b"HTTP/1.1 503"):
                    refused += 1
            except (socket.timeout, ConnectionResetError):
                pass
        assert refused >= 40, refused
    finally:
        for s in held:
            s.close()
    end = time.monotonic() + 30
    while time.monotonic() < end and not alive(url):
        time.sleep(0.2)
    assert alive(url)


def test_canfleet_up_with_web_serves_its_fleet_and_stops_it_with_the_fleet(tmp_path: Path) -> None:
    with up_with_web(PAIR, tmp_path) as url:
        end = time.monotonic() + 60
        while time.monotonic() < end and b"quad-6" not in get(url, "/api/state")[1]:
            time.sleep(0.2)
        assert b"quad-6" in get(url, "/api/state")[1]
        status, body = post(url, {"status": {}})  # its actions reach this fleet's control API
        assert status == 200 and "python-pair" in json.dumps(body)
    with pytest.raises(OSError):
        get(url, "/api/info")  # gone with the fleet
