"""A client of the orchestrator's control API (orchestrator/control/canfleet_control.proto):
protobuf Requests and Responses, varint-delimited, over TCP. One request at a time per client
(a lock), which is what the CLI does too; a refusal raises OrchestratorError with its message."""
from __future__ import annotations

import socket
import threading
from typing import Optional

from . import endpoints
from ._proto import control as pb
from .errors import NotReachableError, OrchestratorError, SdoAbortError
from .framing import DelimitedReader, FramingError, delimited

DEFAULT_TIMEOUT = 30.0  # seconds, as the CLI's --timeout (an SDO block transfer can take a while)


class ControlClient:
    """Request/response over one connection to the control API at `endpoint` (tcp://HOST:PORT)."""

    def __init__(self, endpoint: str, timeout: float = DEFAULT_TIMEOUT, token: Optional[str] = None) -> None:
        """`token`: the fleet's, for an orchestrator beyond loopback; None: from the environment
        (canfleet.auth.resolve: CANFLEET_TOKEN_FILE, CANFLEET_TOKEN)."""
        self.endpoint = endpoint
        self.timeout = timeout
        self.token = token
        self._lock = threading.Lock()
        self._sock: Optional[socket.socket] = None
        self._reader = DelimitedReader()
        self._next_id = 1

    def _connect(self) -> socket.socket:
        if self._sock is None:
            try:
                self._sock = endpoints.connect(self.endpoint, self.timeout, self.token)
            except OSError as e:
                raise NotReachableError(f"no orchestrator at {self.endpoint} ({e.strerror or e})") from None
            self._reader = DelimitedReader()
        return self._sock

    def call(self, request: pb.Request, timeout: Optional[float] = None) -> pb.Response:
        """Sends `request` (its id is set here) and returns the Response. Raises OrchestratorError
        (SdoAbortError for an SDO abort) when the orchestrator refused, NotReachableError when it
        cannot be reached or the connection broke."""
        with self._lock:
            sock = self._connect()
            request.id = self._next_id
            self._next_id += 1
            try:
                sock.settimeout(timeout if timeout is not None else self.timeout)
                sock.sendall(delimited(request.SerializeToString()))
                response = self._receive(sock, request.id)
            except OrchestratorError:
                self._drop()
                raise
            except (OSError, FramingError) as e:
                refusal = self._refusal(sock)
                self._drop()
                if refusal:
                    raise OrchestratorError(f"the orchestrator at {self.endpoint} {refusal}") from None
                raise NotReachableError(f"control connection to {self.endpoint} failed: {e}") from None
        if response.error:
            raise SdoAbortError.parse(response.error, request.WhichOneof("body") or "")
        return response

    def _receive(self, sock: socket.socket, request_id: int) -> pb.Response:
        while True:
            body = self._reader.next()
            if body is not None:
                response = pb.Response()
                response.ParseFromString(body)
                if response.id == request_id:
                    return response
                if response.id == 0 and response.error:
                    # The connection itself was refused (no or wrong token, too many clients).
                    raise OrchestratorError(f"the orchestrator at {self.endpoint} {response.error}")
                continue  # an answer to a request given up on earlier
            data = sock.recv(65536)
            if not data:
                raise OSError("the orchestrator closed the connection")
            self._reader.feed(data)

    def _refusal(self, sock: socket.socket) -> str:
        """A refusal the orchestrator sent before closing (its error Response with id 0), if one
        is still waiting in the reader or the socket: a send may fail before it is read."""
        try:
            sock.setblocking(False)
            self._reader.feed(sock.recv(65536))
        except OSError:
            pass
        while True:
            try:
                body = self._reader.next()
            except FramingError:
                return ""
            if body is None:
                return ""
            response = pb.Response()
            response.ParseFromString(body)
            if response.id == 0 and response.error:
                return response.error

    def _drop(self) -> None:
        if self._sock is not None:
            try:
                self._sock.close()
            finally:
                self._sock = None

    def close(self) -> None:
        with self._lock:
            self._drop()

    def __enter__(self) -> "ControlClient":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ = ["ControlClient", "OrchestratorError", "DEFAULT_TIMEOUT"]
