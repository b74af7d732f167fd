"""Replay timing: appmode's `play` beside python-can's MessageSync, same schedule, one run.

10,000 events at 10 ms spacing (100 s each by default). For every event: how late it was
sent against start + its recorded time. Prints median and p99 lateness, and the drift at
the end (lateness of the last event). Target for appmode: p99 under 1 ms, no drift.
Needs python-can for the side-by-side column: pip install python-can.
"""

from __future__ import annotations

import argparse
import statistics
import time

from common import percentile

from appmode.transcript.replay import play


def appmode_lateness(times: list[float]) -> list[float]:
    return play([(t, b"A") for t in times], lambda data: None, clock=time.perf_counter)


def python_can_lateness(times: list[float]) -> list[float] | None:
    try:
        import can
    except ImportError:
        return None
    messages = [can.Message(timestamp=t, arbitration_id=1, data=b"A") for t in times]
    lateness = []
    start = None
    for message in can.MessageSync(messages, timestamps=True, gap=0.0001, skip=60.0):
        now = time.perf_counter()
        if start is None:
            start = now
        lateness.append(now - (start + message.timestamp - times[0]))
    return lateness


def row(name: str, lateness: list[float]) -> str:
    ms = [x * 1000 for x in lateness]
    return (
        f"{name:<22} {statistics.median(ms):>9.3f} {percentile(ms, 99):>9.3f} "
        f"{max(ms):>9.3f} {ms[-1]:>11.3f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--events", type=int, default=10_000)
    parser.add_argument("--spacing", type=float, default=0.010, metavar="S")
    args = parser.parse_args()
    times = [k * args.spacing for k in range(args.events)]
    print(
        f"replay of {args.events} events at {args.spacing * 1000:g} ms spacing "
        f"({times[-1]:.0f} s each); lateness against the recorded schedule, in ms"
    )
    print(f"{'':<22} {'median':>9} {'p99':>9} {'max':>9} {'drift(end)':>11}")
    print(row("appmode play", appmode_lateness(times)), flush=True)
    can_result = python_can_lateness(times)
    if can_result is None:
        print(f"{'python-can MessageSync':<22} (not installed: pip install python-can)")
    else:
        print(row("python-can MessageSync", can_result))


if __name__ == "__main__":
    main()
