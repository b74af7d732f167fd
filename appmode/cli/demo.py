"""`appmode demo`: the simulated board driven through a short scripted route."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from typing import TextIO

from appmode.board.profiles import SHEET, Profile, profile_named
from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_profile
from appmode.protocol import app
from appmode.protocol.drive_types import DRIVE_NAMES, DriveType

ROUTE: tuple[tuple[float, app.Command], ...] = (
    (0.00, app.ReadParams()),
    (0.20, app.SwitchPage("J")),
    (0.30, app.Move(1)),  # A: forward
    (1.00, app.Move(3)),  # C: right (turn in place on a differential drive)
    (1.60, app.SwitchPage("K")),
    (1.70, app.Move(7)),  # G on the button page: rotate counter-clockwise
    (2.30, app.Stop()),
    (2.50, app.SetParam(0, 800)),
    (2.60, app.ReadParams()),
)
END = 3.0


def run_demo(
    out: TextIO,
    drive: DriveType | None = DriveType.MECANUM,
    sleep: Callable[[float], None] | None = time.sleep,
    profile: Profile = SHEET,
) -> int:
    """Print each command sent and each record decoded, at its time; returns records seen.

    With `sleep=None` the route runs on virtual time, as fast as it can. On a profile whose
    motors are off after power-up the route starts once they are on.
    """
    from appmode.board.firmware import Board  # here: start-up stays short
    from appmode.protocol.render import describe, line

    board = Board(drive=drive if profile.drive_types else None, profile=profile)
    layout = profile.a_layout
    decoder = layout.board_decoder()
    started = time.monotonic()
    start = profile.dead_time + 0.2 if profile.dead_time else 0.0
    end = start + END
    kind = f"{drive.cli_name} drive" if drive and profile.drive_types else "no drive types"
    if profile is not SHEET:
        kind = f"{profile.name} profile, {kind}"
    out.write(f"SIMULATED board ({kind}), scripted route of {end:.1f} s\n")
    records = 0
    schedule = [(round(start + t, 3), command) for t, command in ROUTE]
    now = 0.0
    while now <= end + 1e-9:
        if sleep is not None:
            sleep(max(0.0, started + now - time.monotonic()))
        for event in decoder.feed(board.poll(now)):
            records += isinstance(event, app.Velocity | app.Attitude | app.ParamsRecord)
            out.write(line(now, "<", event.raw, describe(event, layout)) + "\n")
        while schedule and schedule[0][0] <= now + 1e-9:
            _, command = schedule.pop(0)
            data = app.encode(command)
            board.receive(data, now)
            out.write(line(now, ">", data, describe(command)) + "\n")
        out.flush()
        now = round(now + 0.05, 3)
    return records


def register(sub: Subparsers) -> argparse.ArgumentParser:
    demo = sub.add_parser(
        "demo",
        help=COMMANDS["demo"],
        description="Boot the simulated board, drive a scripted route (page switch, "
        "directions, stop, parameter set and read) and print each command and decoded record.",
    )
    demo.add_argument(
        "--drive",
        choices=DRIVE_NAMES,
        default="mecanum",
        help="drive type of the simulated board (default: mecanum)",
    )
    add_profile(
        demo,
        "the simulated board's behaviour: sheet, minibalance (the reference firmware, "
        "see appmode protocol 13; it has no drive types), balance or a profile FILE (its "
        "records and parameters, no physics)",
    )
    demo.add_argument(
        "--fast", action="store_true", help="run on virtual time instead of real time"
    )
    return demo


def run(args: argparse.Namespace) -> int:
    run_demo(
        sys.stdout,
        DriveType.from_cli_name(args.drive),
        None if args.fast else time.sleep,
        profile_named(args.profile),
    )
    return 0
