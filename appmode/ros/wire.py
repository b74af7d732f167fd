"""What rides with a ROS sample on rmw_zenoh, with no I/O (docs/design.md,
"Publishers"; attachment_helpers.cpp): the attachment — the sequence number and the
source time in ns since the UNIX epoch, each an int64 little-endian, then the
publisher's GID, 16 bytes after its length (zenoh-ext's serialization of the three) —
and the GID itself, the XXH3-128 of the entity's liveliness token, its low 64 bits
first (liveliness_utils.cpp, `Entity::Entity`)."""

from __future__ import annotations

import struct
from typing import NamedTuple

import xxhash

GID_SIZE = 16
ATTACHMENT = struct.Struct(f"<qqB{GID_SIZE}s")


class Attachment(NamedTuple):
    sequence: int
    time_ns: int
    gid: bytes


def attachment(sequence: int, time_ns: int, gid: bytes) -> bytes:
    return ATTACHMENT.pack(sequence, time_ns, GID_SIZE, gid)


class BadAttachment(ValueError):
    """An attachment that is not rmw_zenoh's."""


def read_attachment(data: bytes) -> Attachment:
    """A sample's attachment; BadAttachment if it is not 33 bytes of the form."""
    if len(data) != ATTACHMENT.size:
        raise BadAttachment(f"{len(data)} bytes, not {ATTACHMENT.size}")
    sequence, time_ns, size, gid = ATTACHMENT.unpack(data)
    if size != GID_SIZE:
        raise BadAttachment(f"a GID of {size} bytes, not {GID_SIZE}")
    return Attachment(sequence, time_ns, gid)


def gid(token: str) -> bytes:
    """An entity's GID: XXH3-128 of its token, the low 64 bits then the high, each as
    the machine stores it (little-endian on every platform ROS 2 runs on)."""
    digest = xxhash.xxh3_128_intdigest(token.encode())
    return struct.pack("<QQ", digest & (2**64 - 1), digest >> 64)
