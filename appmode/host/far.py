"""Threads waiting for a far end that is itself the car's stop authority (a shared car's
host) to acknowledge a write. The stop guard counts such a wait as the link's, not as a
view that stalls: the far end stops the car itself when this client falls silent to it,
and a stop from here would wait behind that write on the same link. The write bounds
the wait (a shared car's: one second)."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

_waiting: set[int] = set()
"""Native ids of the threads in a far wait (a set's add and discard are atomic)."""


@contextmanager
def acknowledging() -> Iterator[None]:
    """This thread waits for the far end's acknowledgement while inside."""
    me = threading.get_native_id()
    _waiting.add(me)
    try:
        yield
    finally:
        _waiting.discard(me)


def waiting(thread: int) -> bool:
    """Whether `thread` (a native id) waits for a far end's acknowledgement now."""
    return thread in _waiting
