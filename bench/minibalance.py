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

from appmode.host.app.client import Host
from appmode.ports.urls import open_link
from appmode.protocol.app import ParamsRecord
from appmode.protocol.app_decoders import BoardDecoder
from bench.common import Row, board, percentile


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


def rows(trials: int) -> list[Row]:
    with board("--pty", "--profile", "minibalance") as url:
        trips = round_trips(url, trials)
        reads, sets = verified(url, trials)
    out = []
    trip = sorted(v * 1000 for v in trips)
    two_trips = 2 * trip[len(trip) // 2] + 40  # two median round trips, and a pass's slack
    for label, values, target, limit in (
        ("minibalance, pty: {Q:P} -> C round trip", trips, "35-100 ms (next pass)", 100.0),
        ("minibalance, pty: appmode read (2 C agree)", reads, "2 round trips", two_trips),
        ("minibalance, pty: appmode verified set", sets, "2 round trips", two_trips),
    ):
        ms = sorted(v * 1000 for v in values)
        out.append(
            Row(
                label,
                f"median {ms[len(ms) // 2]:.1f} ms, p99 {percentile(ms, 99):.1f} ms, "
                f"max {ms[-1]:.1f} ms (n={len(ms)})",
                target if limit == 100.0 else f"{target} (median < {limit:.0f} ms)",
                (ms[0] >= 35 and ms[-1] <= 100) if limit == 100.0 else ms[len(ms) // 2] < limit,
            )
        )
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--trials", type=int, default=100)
    args = parser.parse_args()
    for row in rows(args.trials):
        print(f"{row.benchmark}: {row.result} (target: {row.target}; met: {row.met})")


if __name__ == "__main__":
    main()
