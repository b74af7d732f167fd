"""A stranger's idle connections: `python -m tests.support.idle_connections HOST PORT N`
opens N TCP connections to HOST:PORT, says `ready`, and keeps them open, saying
nothing on them, until it is ended (SIGTERM) or the far side closes them."""

from __future__ import annotations

import signal
import socket
import sys


def main(host: str, port: int, count: int) -> None:
    held = []
    for _ in range(count):
        try:
            held.append(socket.create_connection((host, port), timeout=5))
        except OSError:
            break
    print(f"ready {len(held)}", flush=True)
    signal.sigwait({signal.SIGTERM, signal.SIGINT})


if __name__ == "__main__":
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM, signal.SIGINT})
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]))
