"""The fleet's token (bus/wire/auth_token.hpp): what a client sends first on a TCP connection to an
orchestrator or broker that listens beyond loopback. The same sources as the C++ tools: a file
given explicitly, else the file named by CANFLEET_TOKEN_FILE (a Docker secret), else CANFLEET_TOKEN."""
from __future__ import annotations

import os
from typing import Optional

MAGIC = b"CFAUTH1 "
MIN_LENGTH = 16
MAX_LENGTH = 255


class TokenError(ValueError):
    """A token file or variable that cannot be used; the message names it."""


def problem(token: str) -> str:
    """Why `token` cannot be used ("" if it can)."""
    if not MIN_LENGTH <= len(token) <= MAX_LENGTH:
        return f"a token has {MIN_LENGTH}..{MAX_LENGTH} characters, this one {len(token)}"
    if any(not ("!" <= c <= "~") for c in token):
        return "a token is printable ASCII without spaces"
    return ""


def read_token_file(path: str) -> str:
    try:
        with open(path, encoding="ascii", errors="replace") as f:
            token = f.readline().strip()
    except OSError as e:
        raise TokenError(f"token file {path}: cannot be read ({e.strerror or e})") from None
    if not token:
        raise TokenError(f"token file {path}: its first line is empty")
    why = problem(token)
    if why:
        raise TokenError(f"token file {path}: {why}")
    return token


def resolve(token_file: Optional[str] = None) -> Optional[str]:
    """The token from `token_file`, CANFLEET_TOKEN_FILE or CANFLEET_TOKEN; None when none is set."""
    if token_file:
        return read_token_file(token_file)
    path = os.environ.get("CANFLEET_TOKEN_FILE")
    if path:
        return read_token_file(path)
    value = os.environ.get("CANFLEET_TOKEN", "").strip()
    if value:
        why = problem(value)
        if why:
            raise TokenError(f"CANFLEET_TOKEN: {why}")
        return value
    return None


def preamble(token: str) -> bytes:
    """The bytes that carry `token` ahead of a client's first message."""
    raw = token.encode("ascii")
    return MAGIC + bytes([len(raw)]) + raw


__all__ = ["TokenError", "resolve", "read_token_file", "preamble", "problem"]
