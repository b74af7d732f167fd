"""A key holder's own Zenoh peer, joined to a car's host with the key, that clients may
join in turn (one that scouts finds it as it finds the car's): `python -m
tests.support.own_peer LISTEN CONNECT KEY NAME`. It speaks for the car with a signer of
its own making — the car at rest and nobody driving, every stop confirmed — and tells
every driver it hears that it was dropped; it prints `ready`, then a line for each
query it answered (`answered KEY`), until SIGTERM."""

from __future__ import annotations

import json
import signal
import sys
import threading
import time
from typing import Any

from appmode.net.config import close_session, open_session
from appmode.net.names import Keys
from appmode.net.signature import Signer

FORGED = {"driver": None, "moving": False, "in_force": None, "sent": True, "confirmed": True}


def main(listen: str, connect: str, key: str, name: str) -> None:
    import zenoh

    keys, signer = Keys(name), Signer("a key holder's own host key")
    session = open_session("peer", key, listen=(listen,), connect=(connect,))
    ended = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: ended.set())
    started = time.monotonic()

    def answer(query: zenoh.Query) -> None:
        at = str(query.key_expr).replace("*", name)
        body = {**FORGED, "name": name, "time": 1e6, "ports": ["app"], "links": {"app": True}}
        signer.reply(query, at, json.dumps(body))
        print(f"answered {at}", flush=True)

    def drop(sample: zenoh.Sample) -> None:
        client = sample.payload.to_string().split(" ")[0]
        said = {"t": "dropped", "at": 1e6 + time.monotonic() - started, "client": client}
        signer.put(events, keys.events, json.dumps({**said, "why": "FORGED"}))

    events = session.declare_publisher(keys.events)
    declared: list[Any] = [
        session.declare_queryable(key_expr, answer)
        for key_expr in (keys.info, keys.stop, "appmode/*/info", "appmode/*/stop")
    ]
    declared.append(session.declare_subscriber(keys.alive, drop))
    print("ready", flush=True)
    try:
        ended.wait()
    finally:
        for each in declared:
            each.undeclare()
        close_session(session)


if __name__ == "__main__":
    main(*sys.argv[1:5])
