"""How busy the machine is now, for tests that pace themselves to it."""

from __future__ import annotations

import os
import time


def busy_cores(seconds: float = 0.25, looks: int = 1) -> float:
    """Cores' worth of CPU in use now: on Linux measured over `seconds` (/proc/stat), the
    least of `looks` such windows in a row (a program that keeps a core busy shows in
    each; a run's last processes ending, in one or two), elsewhere the one-minute load
    average. The load average alone still counted a run that had just ended: the next,
    started within a minute or so on an idle machine, took two workers, not three, and
    ran 6 min 15 s, not 4 min 30."""
    return min(_busy(seconds) for _ in range(looks))


def _busy(seconds: float) -> float:
    try:
        before = _cpu_times()
        time.sleep(seconds)
        after = _cpu_times()
    except (OSError, ValueError):
        return os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
    total = sum(after) - sum(before)
    idle = after[3] + after[4] - before[3] - before[4]  # idle, iowait
    return (os.cpu_count() or 1) * (total - idle) / total if total > 0 else 0.0


def _cpu_times() -> list[int]:
    """The machine's CPU time by kind (user, nice, system, idle, iowait, …): /proc/stat."""
    with open("/proc/stat") as stat:
        return [int(field) for field in stat.readline().split()[1:]]
