"""What a query or sample to a shared car's host says, read as data from outside (a key
holder may send anything): text that may not be UTF-8, who asks (only for the query's
own key: a wildcard, `get appmode/**`, asks for nothing that acts), its JSON."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

from appmode.host.link import CHUNK
from appmode.net.proof import Proof

if TYPE_CHECKING:
    import zenoh

MAX_CLIENT = 128
"""Characters of a client's name at most (appmode's: its machine, process and a token)."""
MAX_ASKED = MAX_CLIENT + 96
"""Characters of a query's attachment at most: its client, a deadline, a proof."""
NOT_ASKED = "not a query of this car's (its own key, a client's printable name, JSON)"


def text_of(data: zenoh.ZBytes | None) -> str | None:
    """The bytes as text; None when they are not UTF-8."""
    try:
        return "" if data is None else data.to_string()
    except ValueError:
        return None


def asked_by(query: zenoh.Query, key: str) -> list[str] | None:
    """What the query's attachment says, a word at a time (its client first, as
    appmode's name theirs: printable, at most MAX_CLIENT characters), when the query is
    for `key` itself (a wildcard, `get appmode/**`, is nobody's write or lease); else
    None."""
    text = text_of(query.attachment)
    if str(query.key_expr) != key or not text or len(text) > MAX_ASKED:
        return None
    words = text.split(" ")
    if not words[0] or len(words[0]) > MAX_CLIENT or not text.isprintable():
        return None
    return words


def proof_of(words: list[str], plain: int) -> Proof | None:
    """The proof after a message's `plain` words, if it carries one."""
    return Proof.parse(words) if len(words) == plain + 2 else None


def write_refusal(words: list[str] | None, data: bytes, now: float) -> str | None:
    """Why a write (its attachment's `words`, as `asked_by` found them: `CLIENT UNTIL`,
    UNTIL the time on the car's clock after which the client has given the write up,
    then its proof) is refused before its lease is asked (None: it is not): no client,
    more than a chunk (a client's link writes one at a time), or past its client's
    deadline (it was held up on the network: written now, it would move a car its driver
    was told did not take it)."""
    if words is None or len(words) < 2:
        return NOT_ASKED
    if len(data) > CHUNK:
        return f"a write of {len(data)} bytes: at most {CHUNK} at a time"
    try:
        deadline = float(words[1])
    except ValueError:
        return NOT_ASKED
    if not math.isfinite(deadline):
        return NOT_ASKED
    if now > deadline:
        return f"not written: it came {now - deadline:.1f} s after its client gave it up"
    return None


def json_of(query: zenoh.Query) -> dict[str, Any] | None:
    """The query's JSON object ({} for none); None when it is something else."""
    text = text_of(query.payload)
    if not text:
        return None if text is None else {}
    return json_object(text)


def json_object(data: str | bytes) -> dict[str, Any] | None:
    """`data`'s JSON object; None for anything else (what comes from outside is read as
    data: never trusted to be well formed)."""
    try:
        found = json.loads(data)
    except ValueError:  # not JSON, or not UTF-8
        return None
    return found if isinstance(found, dict) else None
