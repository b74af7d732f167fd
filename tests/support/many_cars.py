"""`python -m tests.support.many_cars N LISTEN KEY`: N simulated cars shared from one
process on one Zenoh session (as N `appmode share sim://` would share them, without N
interpreters on a two-core machine), named car-01…; prints `ready` when all are shared,
runs until SIGTERM, then stops every car as `share` does."""

from __future__ import annotations

import signal
import sys
import threading

from appmode.net.config import close_session, open_session
from appmode.net.share import Share
from appmode.net.signature import Signer
from appmode.ports.choice import choose
from appmode.ports.target import parse_target


def _log(text: str) -> None:
    print(text, file=sys.stderr)


def main(count: int, listen: str, key: str) -> None:
    session = open_session("peer", key, listen=(listen,), scout=True)
    ended = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: ended.set())
    shares: list[Share] = []
    signer = Signer("many cars' host key")
    try:
        for n in range(1, count + 1):
            choice = choose(parse_target("sim://"), both=True)
            shares.append(Share(session, f"car-{n:02}", choice, _log, signer))
        runs = [threading.Thread(target=s.run, args=(ended.is_set,), daemon=True) for s in shares]
        for run in runs:
            run.start()
        print("ready", flush=True)
        ended.wait()
        for run in runs:
            run.join()
    finally:
        for share in shares:
            share.close()
        close_session(session)


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2], sys.argv[3])
