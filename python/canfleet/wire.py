"""The node wire protocol (bus/wire/canfleet_wire.proto) from the client's side: Envelopes with
their varint length prefix, and frames as the packed 24-byte records of FrameBatch.records.

Record layout (little-endian; the .proto's comment is the reference):
  0..7 int64 time_ns | 8..11 uint32 id | 12 uint8 dlc | 13 uint8 flags (01 extended, 02 remote,
  04 error) | 14..15 reserved 0 | 16..23 data (bytes beyond the DLC written as 0)
"""
from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Iterator, List

from ._proto import WIRE_PROTOCOL_VERSION
from ._proto import wire as pb
from .framing import delimited

#: The version this package speaks (generated from bus/wire/messages.hpp). A module attribute so
#: that a test can pretend to be another version.
PROTOCOL_VERSION = WIRE_PROTOCOL_VERSION

RECORD = struct.Struct("<qIBBxx8s")
FLAG_EXTENDED = 0x01
FLAG_REMOTE = 0x02
FLAG_ERROR = 0x04


@dataclass(frozen=True)
class Record:
    time_ns: int
    can_id: int
    dlc: int
    flags: int
    data: bytes  # dlc bytes (none for a remote frame)


def encode_records(frames: List[Record]) -> bytes:
    out = bytearray()
    for f in frames:
        out += RECORD.pack(f.time_ns, f.can_id, f.dlc, f.flags, f.data.ljust(8, b"\0"))
    return bytes(out)


def decode_records(records: bytes) -> Iterator[Record]:
    if len(records) % RECORD.size:
        raise ValueError(f"frame records of {len(records)} bytes: not a multiple of {RECORD.size}")
    for time_ns, can_id, dlc, flags, data in RECORD.iter_unpack(records):
        if dlc > 8:
            raise ValueError(f"frame record with DLC {dlc}")
        yield Record(time_ns, can_id, dlc, flags, b"" if flags & FLAG_REMOTE else data[:dlc])


def envelope(**body: object) -> bytes:
    """One Envelope with its length prefix: envelope(frames=pb.FrameBatch(...))."""
    return delimited(pb.Envelope(**body).SerializeToString())  # type: ignore[arg-type]
