"""The cars a key opens: every share that answers (`appmode/*/info`), each with how long
its answer took; and the stop of all of them, each car's host saying whether its stop
took (on the car's A records, where it sends them)."""

from __future__ import annotations

import json
import socket
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from appmode.net.names import ANY_INFO, ANY_STOP, Keys, name_of
from appmode.ports.remote import NAME

if TYPE_CHECKING:
    import zenoh

ASK = 2.0
"""Seconds to wait for the cars' answers."""
STOPPING = 4.0
"""Seconds to wait for the cars' answers to a stop (each confirms within a second)."""


@dataclass(frozen=True, slots=True)
class Car:
    """A shared car as its host describes it, and the round trip of asking."""

    name: str
    info: dict[str, Any]
    latency_ms: float


def cars(session: zenoh.Session, wait: float = ASK) -> list[Car]:
    """Every car that answers within `wait` seconds, by name."""
    import zenoh

    sent = time.monotonic()
    found: dict[str, Car] = {}
    replies = session.get(
        ANY_INFO,
        target=zenoh.QueryTarget.ALL,
        consolidation=zenoh.ConsolidationMode.NONE,  # two hosts of one name: both heard
        timeout=wait,
    )
    for reply in replies:
        if reply.ok is None:
            continue
        info = _object(reply.ok)
        key = str(reply.ok.key_expr)
        name = name_of(key)
        if info is not None and NAME.fullmatch(name) and key == Keys(name).info:  # a forged
            # 20,000-character name, or a wildcard's (`**`) reply: none
            found[name] = Car(name, info, (time.monotonic() - sent) * 1000)
    return [found[name] for name in sorted(found)]


def stop_all(session: zenoh.Session, wait: float = STOPPING) -> list[dict[str, Any]]:
    """Stop every car; each car's answer: `name`, `sent` (its stop went out),
    `confirmed` (its A records showed it at rest; None: it sends none)."""
    import zenoh

    who = socket.gethostname()
    replies = session.get(
        ANY_STOP,
        target=zenoh.QueryTarget.ALL,
        consolidation=zenoh.ConsolidationMode.NONE,  # each host's answer, whatever its name
        attachment=who,
        timeout=wait,
    )
    answers = [
        answer
        for r in replies
        if r.ok is not None
        and (answer := _object(r.ok))
        and str(r.ok.key_expr) == Keys(str(answer.get("name"))).stop  # its own car's
    ]
    return sorted(answers, key=lambda answer: str(answer.get("name")))


def _object(sample: zenoh.Sample) -> dict[str, Any] | None:
    """A reply's JSON object; None for anything else (what a car's host says is read as
    data from outside: shown escaped, never trusted to be well formed)."""
    try:
        found = json.loads(sample.payload.to_string())
    except (ValueError, UnicodeDecodeError):
        return None
    return found if isinstance(found, dict) else None
