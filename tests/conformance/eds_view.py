"""What the suite needs from an EDS, as python-canopen loaded it, plus an independent count of the
file's sub-objects (so a part python-canopen silently dropped would fail the suite)."""
from __future__ import annotations

import configparser
import re
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, Optional

import canopen
from canopen.objectdictionary import ODArray, ODRecord, ODVariable, datatypes

VARIABLE_LENGTH = (datatypes.VISIBLE_STRING, datatypes.OCTET_STRING, datatypes.UNICODE_STRING,
                   datatypes.DOMAIN)


def variables(od: canopen.ObjectDictionary) -> Iterator[ODVariable]:
    """Every sub-object of the dictionary, in index order, without python-canopen's DummyUsage
    entries (indexes 0001h-0007h: data type definitions for dummy mapping, CiA 306 §4.5.4, not
    sections of the file)."""
    for index in sorted(od.indices):
        obj = od[index]
        if index < 0x20:
            continue
        if isinstance(obj, ODVariable):
            yield obj
        elif isinstance(obj, (ODRecord, ODArray)):
            for sub in sorted(obj.subindices):
                yield obj[sub]


def count_sections(path: Path) -> int:
    """Sub-objects in the file by its own sections (CiA 306 §4.6.3): every [XXXX] VAR/DOMAIN and
    every [XXXXsubY]."""
    cp = configparser.RawConfigParser(inline_comment_prefixes=(";",), strict=False)
    cp.optionxform = str
    cp.read(path)
    n = 0
    for section in cp.sections():
        if re.fullmatch(r"[0-9A-Fa-f]{4}", section):
            obj_type = int(cp.get(section, "ObjectType", fallback="0x7"), 0)
            if obj_type in (0x7, 0x2):
                n += 1
        elif re.fullmatch(r"[0-9A-Fa-f]{4}sub[0-9A-Fa-f]+", section, re.IGNORECASE):
            n += 1
    return n


def default_bytes(var: ODVariable) -> bytes:
    """The DefaultValue as the bytes a conforming server sends (CiA 301 §7.1: little-endian).
    CiA 306 §4.6.3.2: a missing/empty DefaultValue of a number is 0."""
    value = var.default
    if var.data_type in VARIABLE_LENGTH:
        if value is None:
            return b""
        return value.encode("ascii") if isinstance(value, str) else bytes(value)
    if value is None:
        value = 0
    if var.data_type in datatypes.SIGNED_TYPES:
        # python-canopen takes a hexadecimal DefaultValue of a signed type as an unsigned number
        # (0xFFFF for INTEGER16 -1): reduce it to the type's range.
        bits = len(var)
        if value >= 1 << (bits - 1):
            value -= 1 << bits
    return var.encode_raw(value)


def normalised_default(var: ODVariable):
    if var.data_type in VARIABLE_LENGTH:
        return var.default
    data = default_bytes(var)
    return var.decode_raw(data)


def access(var: ODVariable) -> str:
    return (var.access_type or "").lower()


def is_read_only(var: ODVariable) -> bool:
    return access(var) in ("ro", "const")


def is_write_only(var: ODVariable) -> bool:
    return access(var) == "wo"


def size_of(var: ODVariable) -> Optional[int]:
    if var.data_type in VARIABLE_LENGTH:
        return None
    return len(var) // 8


def label(var: ODVariable) -> str:
    return f"{var.index:04X}h.{var.subindex} {var.name}"


def pack_le(value: int, size: int) -> bytes:
    return (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little")


__all__ = ["variables", "count_sections", "default_bytes", "normalised_default", "access", "is_read_only",
           "is_write_only", "size_of", "label", "pack_le", "struct"]
