"""Endpoints as canfleet writes them (bus/wire/endpoint.hpp): tcp://HOST:PORT (IPv6 in brackets)
and unix:///absolute/path."""
from __future__ import annotations

import socket
from typing import Optional, Tuple, Union

from . import auth

Address = Union[Tuple[str, int], str]


def parse(endpoint: str) -> Tuple[int, Address]:
    """(address family, address) of an endpoint. Raises ValueError naming what is wrong."""
    if endpoint.startswith("unix://"):
        path = endpoint[len("unix://"):]
        if not path.startswith("/"):
            raise ValueError(f"{endpoint!r}: a unix endpoint takes an absolute path (unix:///path)")
        return socket.AF_UNIX, path
    if endpoint.startswith("tcp://"):
        rest = endpoint[len("tcp://"):]
        if rest.startswith("["):
            host, sep, port = rest[1:].partition("]:")
        else:
            host, sep, port = rest.rpartition(":")
        if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
            raise ValueError(f"{endpoint!r}: expected tcp://HOST:PORT")
        return (socket.AF_INET6 if ":" in host else socket.AF_INET), (host, int(port))
    raise ValueError(f"{endpoint!r}: expected tcp://host:port or unix:///path")


def connect(endpoint: str, timeout: float, token: Optional[str] = None) -> socket.socket:
    """A connected stream socket (blocking, TCP_NODELAY). Raises OSError when nobody listens.
    On TCP, the fleet's token (`token`, else canfleet.auth.resolve(): CANFLEET_TOKEN_FILE or
    CANFLEET_TOKEN) is sent first when there is one: an orchestrator or broker beyond loopback
    lets in only clients that send it; one on loopback takes it or none."""
    family, address = parse(endpoint)
    if family != socket.AF_UNIX and token is None:
        token = auth.resolve()
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.settimeout(timeout)
        sock.connect(address)
        if family != socket.AF_UNIX:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            if token:
                sock.sendall(auth.preamble(token))
        return sock
    except BaseException:
        sock.close()
        raise
