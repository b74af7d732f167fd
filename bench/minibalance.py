"""The minibalance board (docs/protocol.md §13) over a pty, paced, in real time: the
`{Q:P}` → C round trip, and appmode's verified read and set.

The board answers a read in its next pass (records 60 ms apart), so a round trip is the
`{Q:P}`'s 5 ms on the wire, the wait for that pass (up to 60 ms) and the C record's 30 ms
on the wire: 35–100 ms. appmode reports a read only when two C records agree (the line
has no checksum), and a set when those show the value: two round trips each.
"""

from __future__ import annotations

import argparse
import time

from common import board, percentile

from appmode.host.client import Host
from appmode.ports.urls import open_link
from appmode.protocol.app import ParamsRecord
from appmode.protocol.app_decoders import BoardDecoder


def round_trips(url: str, trials: int) -> list[float]:
    """`{Q:P}` written → the C record's last byte read, in seconds."""
    port = open_link(url, timeout=0.2)
    time.sleep(1.6)  # past power-up: the start-up text, and its first pass at 1.4 s (§13)
    out = []
    for k in range(trials):
        time.sleep(0.05 + 0.013 * (k % 7))  # spread the phase against the board's passes
        port.reset_input_buffer()
        decoder = BoardDecoder()
        start = time.monotonic()
        port.write(b"{Q:P}")
        while not any(isinstance(r, ParamsRecord) for r in decoder.feed(port.read(1))):
            if time.monotonic() - start > 2:
                raise SystemExit("no C record in 2 s")
        out.append(time.monotonic() - start)
    port.close()
    return out


def verified(url: str, trials: int) -> tuple[list[float], list[float]]:
    """(verified reads, verified sets) with appmode's host, in seconds."""
    reads: list[float] = []
    sets: list[float] = []
    with Host(url) as host:
        host.read_params()
        for k in range(trials):
            host.poll(0.013 * (k % 7))
            start = time.monotonic()
            host.read_params()
            reads.append(time.monotonic() - start)
            start = time.monotonic()
            host.set_param(0, 100 + k % 2)
            sets.append(time.monotonic() - start)
        host.set_param(0, 30)
    return reads, sets


def rows(trials: int) -> list[tuple[str, str, str]]:
    with board("--pty", "--profile", "minibalance") as url:
        trips = round_trips(url, trials)
        reads, sets = verified(url, trials)
    out = []
    for label, values, target in (
        ("minibalance, pty: {Q:P} -> C round trip", trips, "35-100 ms (next pass)"),
        ("minibalance, pty: appmode read (2 C agree)", reads, "2 round trips"),
        ("minibalance, pty: appmode verified set", sets, "2 round trips"),
    ):
        ms = sorted(v * 1000 for v in values)
        out.append(
            (
                label,
                f"median {ms[len(ms) // 2]:.1f} ms, p99 {percentile(ms, 99):.1f} ms, "
                f"max {ms[-1]:.1f} ms (n={len(ms)})",
                target,
            )
        )
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--trials", type=int, default=100)
    args = parser.parse_args()
    for label, figure, target in rows(args.trials):
        print(f"{label}: {figure} (target: {target})")


if __name__ == "__main__":
    main()
