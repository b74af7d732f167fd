"""Decoding a large input in one call stays linear: the decoders' events hold no cycles,
but a call that builds a million of them makes the cyclic garbage collector walk the
growing result again and again (a 32 MB `feed` ran at half the speed of a 2 MB one).
Such a call pauses the collector; small calls, the usual case, are left alone."""

from __future__ import annotations

import functools
import gc
from collections.abc import Callable

BULK = 1 << 16
"""Bytes from which one call pauses the collector."""

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from typing import TypeVar

    T = TypeVar("T")
    R = TypeVar("R")


def linear(feed: Callable[[T, bytes], R]) -> Callable[[T, bytes], R]:
    """`feed`, with the cyclic collector paused while it decodes BULK bytes or more."""

    @functools.wraps(feed)
    def paused(self: T, data: bytes) -> R:
        if len(data) < BULK or not gc.isenabled():
            return feed(self, data)
        gc.disable()
        try:
            return feed(self, data)
        finally:
            gc.enable()

    return paused
