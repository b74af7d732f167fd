"""Helpers for the benchmark scripts: start `appmode board` and stop it, measure a
process's CPU and wake-ups."""

from __future__ import annotations

import math
import os
import selectors
import statistics
import subprocess
import sys
import time
import tty
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import NamedTuple

from appmode.ports.wakeups import exact_wakeups, select_exactly
from appmode.testing.process import board_process


@contextmanager
def started(command: str, *args: str) -> Iterator[tuple[subprocess.Popen[str], str]]:
    """Run `appmode COMMAND ARGS` until the block ends; yield the process and what its
    first line says after `NAME: ` (the URL a board or the page prints)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "appmode", command, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        if ": " not in line:
            raise SystemExit(f"appmode {command} did not start: {line!r}")
        yield proc, line.split(": ", 1)[1].strip()
    finally:
        proc.terminate()
        proc.wait(10)


@contextmanager
def board(*args: str) -> Iterator[str]:
    """Run `appmode board ARGS`; yield the URL of its APP port."""
    with board_process("--quiet", *args) as served:
        yield served.url


def fitted_slope(xs: Sequence[float], ys: Sequence[float]) -> tuple[float, float]:
    """The least-squares slope of ys over xs, and its standard error."""
    fit = statistics.linear_regression(xs, ys)
    mean = statistics.fmean(xs)
    spread = sum((x - mean) ** 2 for x in xs)
    residuals = sum((y - (fit.slope * x + fit.intercept)) ** 2 for x, y in zip(xs, ys, strict=True))
    return fit.slope, math.sqrt(residuals / (len(xs) - 2) / spread)


def build() -> str:
    """Which appmode the benchmarks measure: the compiled build (README, "The compiled
    build") or pure Python, as a process they start imports it (and this one's, if not
    the same)."""
    probe = "import appmode.board.firmware as m; print(m.__file__)"
    theirs = _build(
        subprocess.run(
            [sys.executable, "-c", probe], capture_output=True, text=True, check=True
        ).stdout.strip()
    )
    module = sys.modules.get("appmode.board.firmware")
    mine = _build(module.__file__ or "") if module is not None else theirs
    return theirs if mine == theirs else f"{theirs} (in its own processes; {mine} in run_all's)"


def _build(path: str) -> str:
    """The build a module at `path` belongs to."""
    return "pure Python" if path.endswith(".py") else "compiled (mypyc)"


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q / 100 * len(ordered)))]


def summary_ms(values: list[float]) -> str:
    ms = [v * 1000 for v in values]
    return (
        f"median {statistics.median(ms):.3f} ms, p99 {percentile(ms, 99):.3f} ms, "
        f"max {max(ms):.3f} ms (n={len(ms)})"
    )


def cpu_seconds(pid: int) -> float:
    """CPU time process `pid` has run, to the nanosecond (/proc/PID/schedstat; the
    tick counts of /proc/PID/stat are samples, too coarse for a 1 % share)."""
    with open(f"/proc/{pid}/schedstat") as stat:
        return int(stat.read().split()[0]) / 1e9


def threads_cpu_seconds(pid: int) -> float:
    """CPU seconds process `pid` has run, all its threads (Zenoh's and the shares')."""
    total = 0
    for task in os.listdir(f"/proc/{pid}/task"):
        with open(f"/proc/{pid}/task/{task}/schedstat") as stat:
            total += int(stat.read().split()[0])
    return total / 1e9


def cpu_share(pid: int, seconds: float) -> float:
    """Process `pid`'s share of a core (%, all its threads) over the next `seconds`."""
    start, at = threads_cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    return (threads_cpu_seconds(pid) - start) / (time.monotonic() - at) * 100


def wakeups(pid: int) -> int:
    """How many times process `pid` has gone to sleep and woken (its voluntary context
    switches): a served board's wake-ups."""
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("voluntary_ctxt_switches:"):
                return int(line.split()[1])
    raise SystemExit(f"no voluntary_ctxt_switches in /proc/{pid}/status")


def written(pid: int) -> tuple[int, int]:
    """The write calls process `pid` has made and the bytes they wrote (/proc/PID/io)."""
    with open(f"/proc/{pid}/io") as io:
        fields = dict(line.split(":") for line in io)
    return int(fields["syscw"]), int(fields["wchar"])


@dataclass(frozen=True)
class Share:
    """A process's CPU share beside its floor, over rounds that measure each in turn."""

    share: float
    """% of a core (median of the rounds)."""
    floor: float
    """% of a core a bare loop takes with the same wake-ups and writes (median)."""
    over: list[float]
    """Each round's share less the floor measured right after it, sorted: on a machine
    whose load comes and goes, a pair measured together is the fair comparison."""
    wakeups: float
    """The process's wake-ups a second (median)."""
    writes: float
    """Its write calls a second (median)."""
    received: float
    """Bytes a second the reader got (median)."""
    floor_wakeups: float
    """The floor's own wake-ups a second, as counted (median)."""
    floor_writes: float
    """The floor's write calls a second (median)."""


ROUND = 3.0
"""Seconds of a round of `share_and_floor`: the process, then its floor, this long each."""


def share_and_floor(pid: int, seconds: float, read: Callable[[], int]) -> Share:
    """Process `pid`'s CPU share (%) while `read()` is called every 50 ms, and its floor
    (`wakeup_floor` with the same wake-ups, write calls and bytes a second), measured in
    turn, in rounds of ROUND seconds each, `seconds` of each in all (at least 4 rounds).

    A round's excess over its floor is noisy on a shared machine (one board's rounds
    spread over about 0.8 % of a core, its medians of 10 rounds from -0.04 to +0.27 %):
    a row held against a target of 0.3 % needs tens of rounds."""
    rounds = max(4, round(seconds / ROUND))
    shares, rates, calls, volumes = [], [], [], []
    floors: list[Floor] = []
    for _ in range(rounds):
        read()  # what came while the floor ran
        start_cpu, start, woken, got = cpu_seconds(pid), time.monotonic(), wakeups(pid), 0
        writes, wrote = written(pid)
        while time.monotonic() - start < seconds / rounds:
            time.sleep(0.05)  # a client reading in batches: its wake-ups are not the board's
            got += read()
        elapsed = time.monotonic() - start
        shares.append((cpu_seconds(pid) - start_cpu) / elapsed * 100)
        rates.append((wakeups(pid) - woken) / elapsed)
        volumes.append(got / elapsed)
        now_writes, now_wrote = written(pid)
        calls.append((now_writes - writes) / elapsed)
        floors.append(
            wakeup_floor(seconds / rounds, rates[-1], calls[-1], (now_wrote - wrote) / elapsed)
        )
    median = statistics.median
    over = sorted(s - f.share for s, f in zip(shares, floors, strict=True))
    return Share(
        median(shares),
        median(f.share for f in floors),
        over,
        median(rates),
        median(calls),
        median(volumes),
        median(f.wakeups for f in floors),
        median(f.writes for f in floors),
    )


def over_floor(cpu: Share) -> str:
    """How far `cpu` is over its floor: the median of the rounds, and their quartiles."""
    low, median, high = statistics.quantiles(cpu.over, n=4)
    return (
        f"{median:+.2f} % over its floor (median of {len(cpu.over)} rounds; quartiles "
        f"{low:+.2f} to {high:+.2f})"
    )


class Row(NamedTuple):
    """A row of the benchmark table."""

    benchmark: str
    result: str
    target: str
    met: bool | None
    """Whether the result meets the target; None for a row with no target of its own."""


def floor_row(cpu: Share) -> Row:
    """The benchmark table's row for `cpu`'s floor."""
    return Row(
        "its floor: a bare loop, same wake-ups and pty writes",
        f"{cpu.floor:.2f} % of a core ({cpu.floor_wakeups:.0f} wake-ups/s, "
        f"{cpu.floor_writes:.0f} writes/s; the board {cpu.wakeups:.0f}, {cpu.writes:.0f})",
        "",
        None,
    )


def over_floor_met(cpu: Share, margin: float = 0.3) -> bool:
    """Whether `cpu`'s median excess over its floor is within `margin` % of a core."""
    return statistics.median(cpu.over) <= margin


class Floor(NamedTuple):
    """What a floor cost and did."""

    share: float
    """% of a core."""
    wakeups: float
    """Its wake-ups a second, as counted (voluntary context switches)."""
    writes: float
    """Its write calls a second."""


def wakeup_floor(seconds: float, rate: float, writes: float, volume: float) -> Floor:
    """CPU of a loop doing nothing but what trickled output needs: `rate` timed wake-ups
    a second, and `writes` write calls a second into a pty, `volume` bytes a second in
    all (the machine's cost, not appmode's). It waits as a served board does (exact
    wake-ups, on a grid from one start): an epoll wait's timeout is whole milliseconds,
    rounded up, and one of 1/110 s woke it 99 times a second."""
    master, slave = os.openpty()
    tty.setraw(slave)
    idle, never = os.pipe()  # a descriptor nothing is written to: select only times out
    sel = selectors.DefaultSelector()
    sel.register(idle, selectors.EVENT_READ)
    per_wakeup = writes / max(rate, 1e-9)
    chunk = b"x" * max(1, round(volume / max(writes, 1e-9)))
    period = 1 / max(rate, 1e-9)
    with exact_wakeups():
        start_cpu, start, woken = time.process_time(), time.monotonic(), wakeups(os.getpid())
        owed = 0.0
        count = wakes = 0
        while (now := time.monotonic()) - start < seconds:
            wakes = max(wakes + 1, math.ceil((now - start) / period))  # late: the next one
            select_exactly(sel, start + min(wakes * period, seconds) - now)
            owed += per_wakeup
            while owed >= 1:
                os.write(master, chunk)
                owed -= 1
                count += 1
                if count % 64 == 0:
                    os.read(slave, 65536)
        elapsed = time.monotonic() - start
        floor = Floor(
            (time.process_time() - start_cpu) / elapsed * 100,
            (wakeups(os.getpid()) - woken) / elapsed,
            count / elapsed,
        )
    sel.close()
    for fd in (master, slave, idle, never):
        os.close(fd)
    return floor
