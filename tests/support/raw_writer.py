"""A key holder's raw writes to a shared car, as no appmode client sends them: `python -m
tests.support.raw_writer ENDPOINT KEY NAME SIZE COUNT [UNTIL]` sends COUNT writes of
SIZE bytes of `A` to the car's APP port one after another (each given up at UNTIL on
the car's clock, if given; else never), proven as a driver's are, with the heartbeats
that keep its lease, and prints each
answer as a line (`ok`, or the error) as it comes, until the first error. With FREEZE
seconds, it stops (heartbeats too) after its first write for that long, as a process
sent SIGSTOP and then SIGCONT."""

from __future__ import annotations

import json
import sys
import threading

from appmode.net.config import close_session, open_session
from appmode.net.names import Keys
from appmode.net.proof import Prover

CLIENT = "raw-writer-1-abc"


def main(
    endpoint: str, key: str, name: str, size: int, count: int, until: str = "", freeze: str = "0"
) -> None:
    until = until or "1e9"
    prover = Prover()
    session = open_session("client", key, connect=(endpoint,))
    keys = Keys(name)
    done = threading.Event()
    awake = threading.Event()
    awake.set()

    def beat() -> None:
        while not done.wait(0.1):
            awake.wait()
            session.put(keys.alive, CLIENT + prover.words("alive", CLIENT))

    threading.Thread(target=beat, daemon=True).start()
    try:
        for _ in range(count):
            data = b"A" * size
            asker = f"{CLIENT} {until}" + prover.words("write", CLIENT, until, data)
            replies = list(session.get(keys.write("app"), payload=data, attachment=asker))
            reply = replies[0] if replies else None
            said = None if reply is None or reply.ok is None else reply.ok.payload.to_string()
            if reply is None:
                print("no answer", flush=True)
            elif said is not None and "at" in json.loads(said):
                prover.secret = json.loads(said).get("secret")
                print("ok", flush=True)
            else:  # refused (signed by the car's host), or a malformed query's error
                print(f"error {said or reply.err.payload.to_string()}", flush=True)
                return  # as a client does once its write is refused
            if float(freeze) and awake.is_set():
                awake.clear()  # frozen: no heartbeat, no write
                done.wait(float(freeze))
                awake.set()
    finally:
        done.set()
        close_session(session)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), *sys.argv[6:])
