"""`conform` against a real-time board: how late its `>` lines reach the board.

A board process on a pty records what it receives (`--record`); `appmode conform --board`
runs a transcript of N sends at 17 ms spacing (off the board's 50 ms slots, while its
telemetry keeps the reader busy). Lateness of send k, measured where the board received
it: (t_k - t_0) - (due_k - due_0). Target: p99 under 2 ms.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

from appmode.transcript.reading import read_transcript
from bench.common import board, summary_ms

SPACING = 0.017
SENT = {bytes([c]) for c in b"ABCDEFGHJ"}


def measure(sends: int) -> list[float]:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        lines = ["# appmode transcript v1", "0.0000 > J"]
        lines += [f"{k * SPACING:.4f} > {'ABCDEFGH'[k % 8]}" for k in range(1, sends)]
        script = folder / "sends.transcript"
        script.write_text("\n".join(lines) + "\n")
        record = folder / "board.transcript"
        with board("--pty", "--record", str(record)) as url:
            done = subprocess.run(
                [sys.executable, "-m", "appmode", "conform", "--board", url, "--yes", str(script)],
                capture_output=True,
                text=True,
            )
            if done.returncode != 0:
                raise SystemExit(f"conform failed: {done.stdout}{done.stderr}")
        entries = read_transcript(record).entries  # also the reads (and Z) around the run
        received = [e for e in entries if e.direction == ">" and e.data in SENT]
    due = [0.0] + [k * SPACING for k in range(1, sends)]
    got = [e.time for e in received[:sends]]
    if len(got) != sends:
        raise SystemExit(f"the board received {len(got)} of {sends} sends")
    return [(t - got[0]) - d for t, d in zip(got, due, strict=True)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sends", type=int, default=600, help="sends (default 600: ~10 s)")
    args = parser.parse_args()
    print(f"conform --board, {args.sends} sends at {SPACING * 1000:.0f} ms: lateness at the board")
    print(summary_ms(measure(args.sends)))


if __name__ == "__main__":
    main()
