"""The cars a key opens: every share that answers (`appmode/*/info`), each with how long
its answer took; and the stop of all of them, each car's host saying whether its stop
took (on the car's A records, where it sends them). Only answers the cars' hosts signed
count (`signature.Trust`): a key holder's own peer is not heard."""

from __future__ import annotations

import secrets
import socket
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from appmode.net.asked import json_object
from appmode.net.names import ANY_INFO, ANY_STOP, Keys, name_of
from appmode.net.signature import Trust
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


def cars(session: zenoh.Session, trust: Trust, wait: float = ASK) -> list[Car]:
    """Every car whose host answers within `wait` seconds, by name."""
    sent = time.monotonic()
    found: dict[str, Car] = {}
    asked = token()
    for reply in trust.replies(ask(session, ANY_INFO, asked, wait), asked):
        info = json_object(reply.payload.to_bytes())
        key = str(reply.key_expr)
        name = name_of(key)
        if info is not None and NAME.fullmatch(name) and key == Keys(name).info:  # a forged
            # 20,000-character name, or a wildcard's (`**`) reply: none
            found[name] = Car(name, info, (time.monotonic() - sent) * 1000)
    return [found[name] for name in sorted(found)]


def stop_all(session: zenoh.Session, trust: Trust, wait: float = STOPPING) -> list[dict[str, Any]]:
    """Stop every car; each car's answer: `name`, `sent` (its stop went out),
    `confirmed` (its A records showed it at rest; None: it sends none)."""
    asked = f"{socket.gethostname()} {token()}"
    answers = [
        answer
        for reply in trust.replies(ask(session, ANY_STOP, asked, wait), asked)
        if (answer := json_object(reply.payload.to_bytes()))
        and str(reply.key_expr) == Keys(str(answer.get("name"))).stop  # its own car's
    ]
    return sorted(answers, key=lambda answer: str(answer.get("name")))


def token() -> str:
    """A query's own token: the answer signed over it answers this query alone."""
    return secrets.token_hex(8)


def ask(session: zenoh.Session, key: str, attachment: str, wait: float, payload: str = "") -> Any:
    """Every answer to a query of `key`, as they come: each host's, whatever its name
    (two hosts of one name: both heard), and whoever else answers (only what the car's
    host signed counts: `Trust`), whichever is nearer."""
    import zenoh

    return session.get(
        key,
        payload=payload or None,
        target=zenoh.QueryTarget.ALL,
        consolidation=zenoh.ConsolidationMode.NONE,
        attachment=attachment,
        timeout=wait,
    )
