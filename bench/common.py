"""Helpers for the benchmark scripts: start `appmode board` and stop it."""

from __future__ import annotations

import statistics
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def board(*args: str) -> Iterator[str]:
    """Run `appmode board ARGS`; yield the URL it prints."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "appmode", "board", "--quiet", *args],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        if not line.startswith("port: "):
            raise SystemExit(f"board did not start: {line!r}")
        yield line.split(" ", 1)[1].strip()
    finally:
        proc.terminate()
        proc.wait(10)


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q / 100 * len(ordered)))]


def summary_ms(values: list[float]) -> str:
    ms = [v * 1000 for v in values]
    return (
        f"median {statistics.median(ms):.3f} ms, p99 {percentile(ms, 99):.3f} ms, "
        f"max {max(ms):.3f} ms (n={len(ms)})"
    )
