"""Start-up: how long `appmode` takes to answer before it does any work, beside
pyserial's own command-line tool, `python -m serial.tools.miniterm --help`.

Each command runs N times as a process (stdin /dev/null, output discarded), after one
untimed run, in turns (miniterm, then each of appmode's, N rounds: a machine that slows
down for a while slows them all); each median is printed with its ratio to miniterm's.
The commands run as an installed program does, from bytecode: the untimed run writes
appmode's cache, and PYTHONDONTWRITEBYTECODE is cleared for them (set, it had every
timed run compile appmode's modules from source, 12 to 14 ms more for `decode`). With
`--importtime MODULE_COUNT`, the modules that `appmode decode` (the four's heaviest)
spends most on follow (`python -X importtime`, cumulative µs).
Targets (TARGETS): issue 64.13's 1.0x miniterm for --help, params --help, drive --help
and decode; issue 28.2's 1.5x for send --help.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

COMMANDS = {
    "miniterm --help": ["-m", "serial.tools.miniterm", "--help"],
    "appmode --help": ["-m", "appmode", "--help"],
    "appmode decode </dev/null": ["-m", "appmode", "decode"],
    "appmode send --help": ["-m", "appmode", "send", "--help"],
    "appmode drive --help": ["-m", "appmode", "drive", "--help"],
    "appmode params --help": ["-m", "appmode", "params", "--help"],
}


TARGETS = {
    "appmode --help": 1.0,
    "appmode decode </dev/null": 1.0,
    "appmode send --help": 1.5,
    "appmode drive --help": 1.0,
    "appmode params --help": 1.0,
}
"""Each command's start-up at most this many times miniterm's."""

ENV = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
"""The commands' environment: bytecode is read and written, as in an installed program."""


def medians_ms(runs: int) -> dict[str, float]:
    """Each of COMMANDS' median start-up, run in turns."""
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    for run in range(runs + 1):
        for name, args in COMMANDS.items():
            start = time.perf_counter()
            subprocess.run(
                [sys.executable, *args],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                env=ENV,
                check=False,
            )
            if run:  # the first writes the bytecode cache
                times[name].append(time.perf_counter() - start)
    return {name: statistics.median(each) * 1000 for name, each in times.items()}


def heaviest(count: int) -> list[tuple[int, str]]:
    """The modules `appmode decode </dev/null` imports, by cumulative microseconds."""
    done = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "appmode", "decode"],
        stdin=subprocess.DEVNULL,
        env=ENV,
        capture_output=True,
        text=True,
        check=False,
    )
    rows = []
    for line in done.stderr.splitlines():
        parts = line.split("|")
        if len(parts) == 3 and parts[1].strip().isdigit():
            rows.append((int(parts[1]), parts[2].strip()))
    return sorted(rows, reverse=True)[:count]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15, help="runs of each (default 15)")
    parser.add_argument("--importtime", type=int, default=0, metavar="N", help="show N modules")
    args = parser.parse_args()
    medians = medians_ms(args.runs)
    base = medians["miniterm --help"]
    for name, ms in medians.items():
        target = f"  (target <= {TARGETS[name]:.1f}x)" if name in TARGETS else ""
        print(f"{name:28} {ms:7.1f} ms  {ms / base:4.2f}x miniterm{target}")
    for micros, module in heaviest(args.importtime):
        print(f"  {micros / 1000:7.1f} ms  {module}")


if __name__ == "__main__":
    main()
