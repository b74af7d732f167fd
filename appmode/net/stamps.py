"""A byte sample's attachment: the car's time of it (seconds, its host's clock), then
its direction (`>`, `<`, `2>`, `2<`)."""

from __future__ import annotations

import struct

STAMP = struct.Struct("<d")


def stamp(time: float, direction: str) -> bytes:
    return STAMP.pack(time) + direction.encode()


def unstamp(attachment: bytes) -> tuple[float, str] | None:
    """A byte sample's (time at the car, direction); None when it is no stamp."""
    try:
        return STAMP.unpack_from(attachment)[0], attachment[STAMP.size :].decode()
    except (struct.error, UnicodeDecodeError):
        return None
