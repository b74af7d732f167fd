"""Parameter reads and verified sets under heavy faults: how many are reported, how many
fail with a clear error, and how many report a wrong value (the target: none).

Each seeded session reads the parameters, then sets velocity_kp to 4242, against
`sim://?faults=HEAVY,seed:N&pace=0`; a reported value is wrong when it differs from the
board's own. About 0.9 s a session: `python -m bench.noisy_reads --sessions 1000 --jobs 2`
takes about 8 minutes (docs/protocol.md §3.3 gives the rule it checks).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.ports.sim import SimSerial

HEAVY = "drop:0.005,corrupt:0.01,dup:0.005,chatter:0.002,split:0.5,delay:0.01"


def session(seed: int) -> tuple[int, int, list[str]]:
    """(queries reported, queries failed clearly, what was reported wrong)."""
    reported = failed = 0
    wrong: list[str] = []
    with Host(f"sim://?faults={HEAVY},seed:{seed}&pace=0") as host:
        link = host.link
        assert isinstance(link, SimSerial) and link.board is not None
        board = link.board
        runs: tuple[tuple[str, Callable[[], tuple[int, ...]]], ...] = (
            ("read", host.read_params),
            ("set", lambda: host.set_param(5, 4242)),
        )
        for name, run in runs:
            try:
                values = run()
            except AppmodeError:
                failed += 1
                continue
            reported += 1
            if list(values) != [int(v) for v in board.params]:
                wrong.append(f"seed {seed} {name}: reported {values}, board {board.params}")
    return reported, failed, wrong


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sessions", type=int, default=1000)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    reported = failed = done = 0
    wrong: list[str] = []
    with ProcessPoolExecutor(args.jobs) as pool:
        for r, f, w in pool.map(session, range(args.sessions), chunksize=10):
            reported, failed, wrong, done = reported + r, failed + f, wrong + w, done + 1
            if sys.stderr.isatty():
                print(f"\r{done}/{args.sessions} sessions", end="", file=sys.stderr)
    print(
        f"{args.sessions} sessions under heavy faults: {reported} queries reported, "
        f"{failed} failed with a clear error, {len(wrong)} reported a wrong value"
    )
    for line in wrong:
        print("  " + line)
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
