"""Length-delimited protobuf framing (protobuf's writeDelimitedTo: a base-128 varint length, then
the message), as both the control API (orchestrator/control/control_protocol.hpp) and the node
wire protocol (bus/wire/stream_decoder.hpp) use it, with their 1 MiB limit."""
from __future__ import annotations

from typing import Optional

MAX_MESSAGE = 1 << 20


class FramingError(Exception):
    """The byte stream is not a sequence of delimited messages within the limit."""


def encode_varint(value: int) -> bytes:
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        if value:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def delimited(body: bytes) -> bytes:
    if len(body) > MAX_MESSAGE:
        raise FramingError(f"message of {len(body)} bytes exceeds the limit of {MAX_MESSAGE}")
    return encode_varint(len(body)) + body


class DelimitedReader:
    """Splits received bytes into message bodies; copes with any split into reads."""

    def __init__(self, max_size: int = MAX_MESSAGE) -> None:
        self._buffer = bytearray()
        self._max = max_size

    def feed(self, data: bytes) -> None:
        self._buffer += data

    def next(self) -> Optional[bytes]:
        """The next complete body, or None when more bytes are needed. Raises FramingError."""
        length = 0
        shift = 0
        for i, byte in enumerate(self._buffer):
            if i >= 10:
                raise FramingError("overlong varint length")
            length |= (byte & 0x7F) << shift
            shift += 7
            if byte & 0x80:
                continue
            if length > self._max:
                raise FramingError(f"message of {length} bytes exceeds the limit of {self._max}")
            end = i + 1 + length
            if len(self._buffer) < end:
                return None
            body = bytes(self._buffer[i + 1:end])
            del self._buffer[:end]
            return body
        return None
