"""Boards per core: N paced boards served by one process, every pty read by a client.

The server runs in a child process (`--serve`), which reports its own CPU time and how
late each board ran after its wake-up was due (the 4 ms timing grid: its p99 is what a
client sees as jitter); the parent reads every board's APP port and counts its records.
Target: 1,000 boards within one core at 20 records/s each, grid p99 < 5 ms.

With `--no-io` the boards are served in this process on a virtual clock, with endpoints
that only count what they are given: the server's own Python, free of the pty writes,
the scheduler and this machine's CPU accounting (a steadier figure to optimise by).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import statistics
import subprocess
import sys
import threading
import time
import tty
from functools import partial
from pathlib import Path
from typing import Any

from appmode.board.firmware import Board
from appmode.board.profiles import SHEET
from appmode.ports.endpoints import PtyEndpoint
from appmode.ports.serve import BoardServer, switched_on
from appmode.protocol.app import RECORDS
from appmode.protocol.app_decoders import BoardDecoder
from bench.common import percentile

ROOT = Path(__file__).resolve().parent.parent


def serve(count: int) -> None:
    """Serve `count` boards (both ports on ptys, as `appmode board --count`) until
    SIGTERM; then print CPU seconds, wall seconds and the grid's lateness as JSON, from a
    second after the parent's go (from the go in a shorter run)."""
    make = partial(PtyEndpoint, link=None, baud=None)
    server = BoardServer(
        [make] * count,
        [Board(now=on) for on in switched_on(count, SHEET)],
        pace=True,
        log=lambda text: None,
        make_uart2=[make] * count,
    )
    signal.signal(signal.SIGTERM, lambda *_: server.stop())
    for i in range(count):
        print(server.urls(i)["app"], flush=True)
    sys.stdin.readline()  # the parent has opened every port
    start = {"cpu": time.process_time(), "wall": time.monotonic()}  # until measure() runs
    server.lateness = []

    def measure() -> None:
        """From here: a second after the parent's go, once the boards that fell due while
        it opened the ports have run (the first pass ran them 0.1 s late, all at once)."""
        start.update(cpu=time.process_time(), wall=time.monotonic())
        server.lateness = []

    timer = threading.Timer(1.0, measure)
    timer.daemon = True  # a run stopped within the second does not wait for it
    timer.start()
    try:
        server.run()
    finally:
        timer.cancel()
        late = [x * 1000 for x in server.lateness]
        print(
            json.dumps(
                {
                    "cpu": time.process_time() - start["cpu"],
                    "wall": time.monotonic() - start["wall"],
                    "p50": statistics.median(late),
                    "p99": percentile(late, 99),
                    "max": max(late),
                }
            ),
            flush=True,
        )
        server.close()


class Counting:
    """An endpoint that counts the writes it is given (no I/O)."""

    baud = None

    def __init__(self, sel: object, log: object) -> None:
        self.writes = 0

    def write(self, data: bytes) -> None:
        self.writes += 1

    def pause(self, paused: bool) -> None:
        """Nothing waits: never paused."""

    def close(self) -> None:
        """Nothing to close."""


def without_io(count: int, seconds: float) -> tuple[float, float]:
    """Serve `count` boards for `seconds` of a virtual clock (after one second of warm-up),
    as fast as they go: (% of a core at real time, µs a write)."""
    endpoints: list[Counting] = []

    def make(sel: object, log: object) -> Any:
        endpoints.append(Counting(sel, log))
        return endpoints[-1]

    boards = [Board(now=on) for on in switched_on(count, SHEET)]
    server = BoardServer(
        [make] * count, boards, pace=True, log=lambda text: None, make_uart2=[make] * count
    )
    clock = 0.0
    server.now = lambda: clock  # type: ignore[method-assign]
    while clock < 1.0:
        clock = server._step()
    writes = sum(e.writes for e in endpoints)
    start = time.perf_counter()
    while clock < 1.0 + seconds:
        clock = server._step()
    elapsed = time.perf_counter() - start
    writes = sum(e.writes for e in endpoints) - writes
    server.close()
    return elapsed / seconds * 100, elapsed / writes * 1e6


def measure(count: int, seconds: float, read: bool = True) -> dict[str, float]:
    """CPU share, records/s per board (min, median) and grid lateness (ms); with `read`
    False nobody opens the boards' ports (their ptys fill, then what they send is
    dropped: records/s are 0)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "bench.many_boards", "--serve", str(count)],
        cwd=ROOT,  # the checkout's appmode, as `appmode board` run there imports it
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert proc.stdin is not None and proc.stdout is not None
    fds: list[int] = []
    try:
        for _ in range(count):
            url = proc.stdout.readline().strip()
            if read:
                fds.append(os.open(url, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK))
                tty.setraw(fds[-1])
        decoders = [BoardDecoder() for _ in fds]
        records = [0] * len(fds)
        proc.stdin.write("go\n")
        proc.stdin.flush()
        start = time.monotonic()
        while time.monotonic() - start < seconds:
            time.sleep(0.1)
            for k, fd in enumerate(fds):
                with contextlib.suppress(BlockingIOError):
                    data = os.read(fd, 65536)
                    records[k] += sum(isinstance(e, RECORDS) for e in decoders[k].feed(data))
        elapsed = time.monotonic() - start
        proc.terminate()
        report = json.loads(proc.stdout.readline())
    finally:
        for fd in fds:
            os.close(fd)
        proc.kill()
        proc.wait()
    rates = sorted(r / elapsed for r in records) if read else [0.0]
    return {
        "share": report["cpu"] / report["wall"] * 100,
        "min": rates[0],
        "median": statistics.median(rates),
        "p50": report["p50"],
        "p99": report["p99"],
        "max": report["max"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("counts", nargs="*", type=int, default=[200, 500, 1000])
    parser.add_argument("--seconds", type=float, default=15.0)
    parser.add_argument("--unread", action="store_true", help="nobody opens the ports")
    parser.add_argument("--no-io", action="store_true", help="serve in-process, no I/O")
    parser.add_argument("--serve", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.serve:
        serve(args.serve)
        return
    if args.no_io:
        for count in args.counts:
            share, micros = without_io(count, args.seconds)
            print(f"{count:5d} boards, no I/O: {share:5.1f} % of a core, {micros:.2f} µs a write")
        return
    for count in args.counts:
        r = measure(count, args.seconds, not args.unread)
        print(
            f"{count:5d} boards: {r['share']:5.1f} % of a core; records/s per board min "
            f"{r['min']:.1f}, median {r['median']:.1f}; grid lateness p50 {r['p50']:.2f} ms, "
            f"p99 {r['p99']:.2f} ms, max {r['max']:.1f} ms",
            flush=True,
        )


if __name__ == "__main__":
    main()
