"""Replay timing: appmode's `play` beside python-can's MessageSync, fairly paired.

Both players run at once, each in its own process, on the same schedule (events every
10 ms) half a period apart, so they share whatever load the machine has at every moment
without waking together; then again in the other order. Each event's lateness is
measured the same way for both: against start + its time, with the start that makes
none early (each player's start is its own; a process scheduled late once at its
start would otherwise shift that player's whole run). Prints median, p99 and max
lateness, and the drift: the slope of each second's least lateness over a run (ms per
minute, a least-squares fit). A player whose schedule slips moves every event's
lateness, its best ones too; a machine that gets busier during a run moves only the
events it delays (the slope of all of them, the trend, shows the load). `play` keeps its
deadlines with exact wake-ups (no timer slack; on Linux 6.12+ a short slice,
appmode/ports/wakeups.py); MessageSync runs as python-can ships it.

`--load busy` runs two busy processes beside them, `--load pytest` the test suite.
Needs python-can for the comparison: pip install python-can.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from appmode.transcript.replay import play
from bench.common import percentile

PLAYERS = ("appmode play", "python-can MessageSync")
ROOT = Path(__file__).resolve().parent.parent


def wait_for(start: float) -> None:
    """Be running at `start` (both players get there the same way)."""
    if (left := start - time.perf_counter() - 0.002) > 0:
        time.sleep(left)
    while time.perf_counter() < start:
        pass


def appmode_times(times: list[float], start: float) -> list[float]:
    items = [(t, b"A") for t in times]
    sent: list[float] = []
    wait_for(start)
    play(items, lambda _: sent.append(time.perf_counter()), clock=time.perf_counter)
    return sent


def can_times(times: list[float], start: float) -> list[float]:
    import can

    messages = [can.Message(timestamp=t, arbitration_id=1, data=b"A") for t in times]
    sent: list[float] = []
    wait_for(start)
    for _ in can.MessageSync(messages, timestamps=True, gap=0.0001, skip=60.0):
        sent.append(time.perf_counter())
    return sent


WORKERS: dict[str, Callable[[list[float], float], list[float]]] = {
    PLAYERS[0]: appmode_times,
    PLAYERS[1]: can_times,
}


def has_python_can() -> bool:
    try:
        import can  # noqa: F401
    except ImportError:
        return False
    return True


def worker(name: str, events: int, spacing: float, start: float) -> None:
    """One player in this process: print each event's send time (perf_counter)."""
    times = [k * spacing for k in range(events)]
    print("\n".join(repr(x) for x in WORKERS[name](times, start)))


def paired(events: int, spacing: float) -> dict[str, list[float]]:
    """Lateness (s) of each player: both at once, half a period apart, in both orders."""
    late: dict[str, list[float]] = {name: [] for name in PLAYERS}
    for first, second in (PLAYERS, PLAYERS[::-1]):
        start = time.perf_counter() + 1.5  # after both have imported what they need
        procs = {
            name: subprocess.Popen(
                [
                    sys.executable,
                    __file__,
                    "--worker",
                    name,
                    "--events",
                    str(events),
                    "--spacing",
                    str(spacing),
                    "--start",
                    repr(start + offset),
                ],
                stdout=subprocess.PIPE,
                text=True,
            )
            for name, offset in ((first, 0.0), (second, spacing / 2))
        }
        for name, proc in procs.items():
            out, _ = proc.communicate()
            if proc.returncode:
                raise SystemExit(f"the {name} worker failed (status {proc.returncode})")
            sent = [float(x) for x in out.split()]
            start = min(x - k * spacing for k, x in enumerate(sent))
            late[name] += [x - (start + k * spacing) for k, x in enumerate(sent)]
    return late


def trend_ms_per_min(lateness: list[float], spacing: float) -> float:
    """The least-squares slope of one run's lateness over its time, in ms a minute."""
    xs = [k * spacing for k in range(len(lateness))]
    return statistics.linear_regression(xs, lateness).slope * 1000 * 60


def drift_ms_per_min(lateness: list[float], spacing: float) -> float:
    """The least-squares slope of each second's least lateness in one run, in ms a
    minute: the schedule's own slip, which load above it does not bend."""
    per = max(1, round(1 / spacing))
    lows = [min(lateness[k : k + per]) for k in range(0, len(lateness), per)]
    return trend_ms_per_min(lows, spacing * per)


LOADS: dict[str, list[list[str]]] = {
    "idle": [],
    "busy": [[sys.executable, "-c", "while True: pass"]] * 2,
    "busy1": [[sys.executable, "-c", "while True: pass"]],
    "pytest": [[sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]],
}


@contextlib.contextmanager
def load(kind: str) -> Iterator[None]:
    """The processes of LOADS[kind] run while the block runs."""
    procs = [
        subprocess.Popen(
            c,
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        for c in LOADS[kind]
    ]
    try:
        yield
    finally:
        for proc in procs:  # the test suite's own boards and consoles with it
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def summary(lateness: list[float], spacing: float) -> dict[str, float]:
    """median, p99, max (ms); drift and trend (ms/min, the worse of the two runs)."""
    ms = [x * 1000 for x in lateness]
    half = len(lateness) // 2
    runs = (lateness[:half], lateness[half:])
    return {
        "median": statistics.median(ms),
        "p99": percentile(ms, 99),
        "max": max(ms),
        "drift": max((drift_ms_per_min(run, spacing) for run in runs), key=abs),
        "trend": max((trend_ms_per_min(run, spacing) for run in runs), key=abs),
    }


def measure(events: int, spacing: float, kind: str) -> dict[str, dict[str, float]] | None:
    """Each player's summary under `kind` of load, or None without python-can."""
    if not has_python_can():
        return None
    with load(kind):
        time.sleep(1.0 if kind != "idle" else 0.0)
        late = paired(events, spacing)
    return {name: summary(values, spacing) for name, values in late.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--events", type=int, default=10_000)
    parser.add_argument("--spacing", type=float, default=0.010, metavar="S")
    parser.add_argument("--load", choices=("idle", "busy", "pytest"), default="idle")
    parser.add_argument("--worker", choices=PLAYERS, help=argparse.SUPPRESS)
    parser.add_argument("--start", type=float, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker, args.events, args.spacing, args.start)
        return
    result = measure(args.events, args.spacing, args.load)
    if result is None:
        raise SystemExit("python-can is needed for the comparison: pip install python-can")
    print(
        f"replay of {args.events} events at {args.spacing * 1000:g} ms, each player twice "
        f"({os.cpu_count()} cores, load: {args.load}); lateness in ms"
    )
    print(f"{'':<24} {'median':>8} {'p99':>8} {'max':>8} {'drift/min':>10} {'trend/min':>10}")
    for name, s in result.items():
        print(
            f"{name:<24} {s['median']:>8.3f} {s['p99']:>8.3f} {s['max']:>8.3f} "
            f"{s['drift']:>10.4f} {s['trend']:>10.4f}"
        )


if __name__ == "__main__":
    main()
