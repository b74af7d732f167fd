"""What a served board's run costs after the process slept: the same work — the board run
over one record period, driving, with the encoder report on (what `appmode board` does
at each record) — timed in a loop and after sleeps of 1 to 100 ms, CPU time of this
thread. On a machine that runs other work while a process sleeps, the caches are cold
when it wakes, and the longer it slept the colder: a board's record comes after the
longest sleep of its pass (about 37 ms at 20 records/s), which is where a board costs
more than its floor (bench/control_port.py's CPU row)."""

from __future__ import annotations

import argparse
import statistics
import time

from appmode.board.firmware import Board
from appmode.protocol import control, settings
from appmode.protocol.params import DriveType

PERIOD = 0.05
"""A record period on the sheet profile: what one run covers."""


def driving_board() -> Board:
    """A mecanum board driven from UART2, the encoder report on, its car at speed."""
    board = Board(drive=DriveType.MECANUM)
    report = control.SetSetting(settings.BY_NAME["system_mode"], 0x41)
    board.receive_uart2(control.encode(report), 0.0)
    board.receive_uart2(control.encode(control.velocity(DriveType.MECANUM, y=200)), 0.0)
    board.poll_ports(1.0)
    return board


def run_cost(sleep: float, runs: int) -> float:
    """The median µs of CPU one run takes after sleeping `sleep` seconds (0: in a loop)."""
    board, now, costs = driving_board(), 1.0, []
    for _ in range(runs):
        if sleep:
            time.sleep(sleep)
        now += PERIOD
        start = time.thread_time_ns()
        board.poll_ports(now)
        costs.append((time.thread_time_ns() - start) / 1000)
    return statistics.median(costs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=150, help="runs for each sleep")
    args = parser.parse_args()
    hot = run_cost(0.0, args.runs * 10)
    print(f"in a loop: {hot:.1f} µs a run")
    for sleep in (0.001, 0.004, 0.012, 0.037, 0.1):
        cost = run_cost(sleep, args.runs)
        print(f"after {sleep * 1000:5.0f} ms asleep: {cost:6.1f} µs a run ({cost / hot:.1f}x)")


if __name__ == "__main__":
    main()
