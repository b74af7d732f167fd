"""`appmode demo`: the simulated board driven through a short scripted route."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TextIO

from . import protocol
from .board import Board
from .params import DriveType
from .render import describe, line

ROUTE: tuple[tuple[float, protocol.Command], ...] = (
    (0.00, protocol.ReadParams()),
    (0.20, protocol.SwitchPage("J")),
    (0.30, protocol.Move(1)),  # A: forward
    (1.00, protocol.Move(3)),  # C: right (turn in place on a differential drive)
    (1.60, protocol.SwitchPage("K")),
    (1.70, protocol.Move(7)),  # G on the button page: rotate counter-clockwise
    (2.30, protocol.Stop()),
    (2.50, protocol.SetParam(0, 800)),
    (2.60, protocol.ReadParams()),
)
END = 3.0


def run_demo(
    out: TextIO,
    drive: DriveType = DriveType.MECANUM,
    sleep: Callable[[float], None] | None = time.sleep,
) -> int:
    """Print each command sent and each record decoded, at its time; returns records seen.

    With `sleep=None` the route runs on virtual time, as fast as it can.
    """
    board = Board(drive=drive)
    decoder = protocol.BoardDecoder()
    started = time.monotonic()
    out.write(f"SIMULATED board ({drive.cli_name} drive), scripted route of {END:.1f} s\n")
    records = 0
    schedule = list(ROUTE)
    now = 0.0
    while now <= END + 1e-9:
        if sleep is not None:
            sleep(max(0.0, started + now - time.monotonic()))
        for event in decoder.feed(board.poll(now)):
            records += isinstance(
                event, protocol.Velocity | protocol.Attitude | protocol.ParamsRecord
            )
            out.write(line(now, "<", event.raw, describe(event)) + "\n")
        while schedule and schedule[0][0] <= now + 1e-9:
            _, command = schedule.pop(0)
            data = protocol.encode(command)
            board.receive(data, now)
            out.write(line(now, ">", data, describe(command)) + "\n")
        out.flush()
        now = round(now + 0.05, 3)
    return records
