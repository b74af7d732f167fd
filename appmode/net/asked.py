"""What a query or sample to a shared car's host says, read as data from outside (a key
holder may send anything): text that may not be UTF-8, who asks (only for the query's
own key: a wildcard, `get appmode/**`, asks for nothing that acts), its JSON."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

from appmode.host.link import CHUNK

if TYPE_CHECKING:
    import zenoh

MAX_CLIENT = 128
"""Characters of a client's name at most (appmode's: its machine, process and a token)."""
NOT_ASKED = "not a query of this car's (its own key, a client's printable name, JSON)"


def text_of(data: zenoh.ZBytes | None) -> str | None:
    """The bytes as text; None when they are not UTF-8."""
    try:
        return "" if data is None else data.to_string()
    except ValueError:
        return None


def asked_by(query: zenoh.Query, key: str) -> str | None:
    """Who asks, when the query is for `key` itself (a wildcard, `get appmode/**`, is
    nobody's write or lease) and names a client as appmode's do: printable text of at
    most MAX_CLIENT characters; else None."""
    client = text_of(query.attachment)
    if str(query.key_expr) != key or not client or len(client) > MAX_CLIENT:
        return None
    return client if client.isprintable() else None


def write_refusal(asker: str | None, data: bytes, now: float) -> tuple[str, str | None]:
    """A write's client (`asker`, as `asked_by` found it: `CLIENT UNTIL`, UNTIL the
    time on the car's clock after which the client has given the write up), and why it
    is refused before its lease is asked (None: it is not): no client, more than a
    chunk (a client's link writes one at a time), or past its client's deadline (it was
    held up on the network: written now, it would move a car its driver was told did
    not take it)."""
    if asker is None:
        return "", NOT_ASKED
    if len(data) > CHUNK:
        return "", f"a write of {len(data)} bytes: at most {CHUNK} at a time"
    client, _, until = asker.rpartition(" ")
    try:
        deadline = float(until) if client else math.nan
    except ValueError:
        deadline = math.nan
    if not math.isfinite(deadline):
        return asker, None
    if now > deadline:
        return client, f"not written: it came {now - deadline:.1f} s after its client gave it up"
    return client, None


def json_of(query: zenoh.Query) -> dict[str, Any] | None:
    """The query's JSON object ({} for none); None when it is something else."""
    text = text_of(query.payload)
    if not text:
        return None if text is None else {}
    try:
        found = json.loads(text)
    except ValueError:
        return None
    return found if isinstance(found, dict) else None
