"""Two versions of `appmode board`, served at once and measured over the same seconds:
what a change to the board or the server saves, free of this machine's load coming and
going (which moves bench/control_port.py's both-ports row by ±0.2 % of a core from one run to
the next, more than most single changes).

Each version is a folder holding an `appmode` package (a `git worktree add` of a
commit, say). Both serve a mecanum board driving on both ports with the encoder report
on, as the both-ports row does, and one client reads all four ports every 50 ms. The
pair is started in both orders, each start measured in rounds: the board started second
has cost less (0.09–0.20 % of a core, in three pairs of runs), so each order's median of
B's share less A's is printed, and their mean is the estimate, with the quartiles of
every round. The same folder twice shows the noise, and a comparison run again may not
agree: one change measured -0.155 % in one run and +0.136 % in another (both start
orders agreeing each time), so a change smaller than about 0.3 % needs many runs.
"""

from __future__ import annotations

import argparse
import statistics
import time
from contextlib import ExitStack
from pathlib import Path

import serial

from bench.common import cpu_seconds
from bench.control_port import drive_reporting, served

Ports = tuple[serial.Serial, serial.Serial]


def drain(ports: Ports) -> None:
    for port in ports:
        port.read(port.in_waiting)


def rounds(roots: tuple[Path, Path], count: int, seconds: float) -> list[tuple[float, float]]:
    """(A's share, B's share) in % of a core, for `count` rounds of `seconds`, the two
    started in the order given (both stopped at the end, or when one fails to start)."""
    with ExitStack() as stack:
        started = []
        for root in roots:
            proc, app, uart2 = stack.enter_context(served("--drive", "mecanum", root=root))
            app_port = stack.enter_context(serial.Serial(app, 9600, timeout=0.1))
            uart2_port = stack.enter_context(serial.Serial(uart2, 115200, timeout=0.1))
            drive_reporting(uart2_port)
            started.append((proc, (app_port, uart2_port)))
        time.sleep(1.0)  # the cars at speed
        shares = []
        for _ in range(count):
            for _, ports in started:
                drain(ports)
            before, begun = [cpu_seconds(proc.pid) for proc, _ in started], time.monotonic()
            while time.monotonic() - begun < seconds:
                time.sleep(0.05)
                for _, ports in started:
                    drain(ports)
            elapsed = time.monotonic() - begun
            a, b = (
                (cpu_seconds(proc.pid) - cpu) / elapsed * 100
                for (proc, _), cpu in zip(started, before, strict=True)
            )
            shares.append((a, b))
        return shares


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("a", type=Path, help="folder holding version A's appmode package")
    parser.add_argument("b", type=Path, help="folder holding version B's appmode package")
    parser.add_argument("--rounds", type=int, default=20, help="rounds per start order")
    parser.add_argument("--seconds", type=float, default=2.0, help="seconds a round")
    args = parser.parse_args()
    for root in (args.a, args.b):
        if not (root / "appmode" / "__init__.py").is_file():
            parser.error(f"{root}: no appmode package there (a git worktree of a commit?)")
    a_first = rounds((args.a, args.b), args.rounds, args.seconds)
    b_first = [(a, b) for b, a in rounds((args.b, args.a), args.rounds, args.seconds)]
    for name, shares in (("A started first", a_first), ("B started first", b_first)):
        print(
            f"{name}: A {statistics.median(a for a, _ in shares):.3f} %, "
            f"B {statistics.median(b for _, b in shares):.3f} % of a core, B - A median "
            f"{statistics.median(b - a for a, b in shares):+.3f} %"
        )
    orders = [statistics.median(b - a for a, b in shares) for shares in (a_first, b_first)]
    low, _, high = statistics.quantiles([b - a for a, b in a_first + b_first], n=4)
    print(
        f"B - A: {statistics.fmean(orders):+.3f} % of a core (the mean of the two orders' "
        f"medians; quartiles of all {2 * args.rounds} rounds {low:+.3f} to {high:+.3f})"
    )


if __name__ == "__main__":
    main()
