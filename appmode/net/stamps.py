"""A byte sample's attachment: the car's time of it (seconds, its host's clock), then
its direction (`>`, `<`, `2>`, `2<`), then, after a space, its host's signature
(`signature`)."""

from __future__ import annotations

import struct

STAMP = struct.Struct("<d")


def stamp(time: float, direction: str) -> bytes:
    return STAMP.pack(time) + direction.encode()


def unstamp(attachment: bytes) -> tuple[float, str, bytes] | None:
    """A byte sample's (time at the car, direction, its stamp as sent: what the
    signature after it covers); None when it is no stamp."""
    end = attachment.find(b" ", STAMP.size)
    stamped = attachment if end < 0 else attachment[:end]
    try:
        return STAMP.unpack_from(stamped)[0], stamped[STAMP.size :].decode(), stamped
    except (struct.error, UnicodeDecodeError):
        return None
