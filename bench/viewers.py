"""Live viewers (issue 68.5): what `--foxglove` costs a driving session, with no viewer,
1 and 10 viewers reading everything, and 10 viewers that connect, subscribe to every
channel and never read again (python -m bench.viewers).

Each run: `appmode drive` on a simulated board served on TCP (paced at 9600 bps, so the
records come as from a car), `drive A`, held for HOLD seconds, then `stop`:

- the session's CPU (all its threads, the SDK's server among them) while it holds `A`;
- the stop on time: on the board's own recording, `Z` after `A`, less the hold.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from bench.common import Row, cpu_share
from tests.support.foxglove_client import watch_sync
from tests.support.processes import ROOT, appmode_cmd, board_process, timed_sent
from tests.viewers.test_live import stalled_viewer

HOLD = 3.0
"""Seconds `A` is held."""


def _run(board_url: str, record: Path, readers: int, stalled: int) -> tuple[float, float]:
    """(CPU %, stop lateness ms) of one drive with these viewers."""
    proc = subprocess.Popen(
        appmode_cmd("drive", board_url, "--foxglove", "0"),
        stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    assert proc.stdin is not None and proc.stderr is not None
    line = proc.stderr.readline()
    found = re.search(r"ws://\S+", line)
    if found is None:
        raise SystemExit(f"drive printed no viewer address: {line!r}")
    url = found.group(0)
    sockets = [stalled_viewer(url) for _ in range(stalled)]
    watchers = [
        threading.Thread(target=watch_sync, args=(url, HOLD + 4), daemon=True)
        for _ in range(readers)
    ]
    for watcher in watchers:
        watcher.start()
    time.sleep(0.8)
    proc.stdin.write(f"drive A\nwait {HOLD}\nstop\n")
    proc.stdin.close()
    time.sleep(0.5)
    cpu = cpu_share(proc.pid, HOLD - 1.0)
    proc.wait(30)
    for sock in sockets:
        sock.close()
    sent = timed_sent(record)
    a = max(t for t, p in sent if p == "A")
    z = next(t for t, p in sent if p == "Z" and t > a)
    return cpu, (z - a - HOLD) * 1000


def rows(quick: bool) -> list[Row]:
    found: list[Row] = []
    cases: tuple[tuple[str, int, int], ...] = (
        ("no viewer", 0, 0),
        ("1 viewer", 1, 0),
        ("10 viewers", 10, 0),
        ("10 viewers never reading", 0, 10),
    )
    if quick:
        cases = cases[::3]
    base = None
    for name, readers, stalled in cases:
        with tempfile.TemporaryDirectory() as folder:
            record = Path(folder) / "board.transcript"
            with board_process("--listen", "0", "--quiet", "--record", str(record)) as board:
                cpu, late = _run(board.url, record, readers, stalled)
        base = cpu if base is None else base
        found.append(
            Row(
                f"drive --foxglove, {name}: CPU; the stop after its time",
                f"{cpu:.1f}% of a core; {late:+.0f} ms",
                "stop within 50 ms of its time; CPU within 10 points of none",
                abs(late) <= 50 and cpu - base <= 10,
            )
        )
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    for row in rows(args.quick):
        print(f"{row.benchmark}: {row.result} (target {row.target}: {row.met})")


if __name__ == "__main__":
    main()
