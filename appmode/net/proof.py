"""A driver's proof that a heartbeat or write is its own. The car's host gives the
client it grants the lease a secret, in the reply only the asker gets; the driver's
heartbeats and queries then carry a count, higher each time, and an HMAC of them and
what they say under that secret. A key holder who sees the heartbeats (every one does)
can neither make the next nor replay one, so it cannot keep a dead driver's car moving
nor drive under the driver's id."""

from __future__ import annotations

import hashlib
import hmac
import itertools
import secrets
from dataclasses import dataclass

SECRET_BYTES = 16
MAC_CHARACTERS = 32
"""Hex digits of an HMAC-SHA256 a message carries (128 bits)."""


def new_secret() -> str:
    return secrets.token_hex(SECRET_BYTES)


def framed(*parts: str | bytes) -> bytes:
    """`parts` as one message, each length-prefixed: no two lists of parts share one."""
    data = [part.encode() if isinstance(part, str) else part for part in parts]
    return b"".join(len(part).to_bytes(4, "big") + part for part in data)


def mac(secret: str, count: int, *parts: str | bytes) -> str:
    """The HMAC of `count` and `parts`."""
    message = framed(str(count), *parts)
    return hmac.new(secret.encode(), message, hashlib.sha256).hexdigest()[:MAC_CHARACTERS]


@dataclass(frozen=True, slots=True)
class Proof:
    """A message's count and HMAC, as it carries them (`COUNT MAC` after its text)."""

    count: int
    mac: str

    @classmethod
    def parse(cls, words: list[str]) -> Proof | None:
        """The proof in a message's last two words, None when they are none."""
        if len(words) < 2 or not words[-2].isdigit() or len(words[-2]) > 19:
            return None
        return cls(int(words[-2]), words[-1])

    def holds(self, secret: str, *parts: str | bytes) -> bool:
        return hmac.compare_digest(self.mac, mac(secret, self.count, *parts))


class Prover:
    """A driver's side: the secret its lease came with, and its count."""

    def __init__(self) -> None:
        self.secret: str | None = None
        self._counts = itertools.count(1)  # next() is one step: the beat's thread and the
        # writer's share it

    def words(self, *parts: str | bytes) -> str:
        """` COUNT MAC` for a message of `parts` ("" before the lease's secret came)."""
        secret = self.secret
        if secret is None:
            return ""
        count = next(self._counts)
        return f" {count} {mac(secret, count, *parts)}"
