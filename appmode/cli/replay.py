"""`appmode replay`: play one side of a transcript to a port."""

from __future__ import annotations

import argparse

from appmode.cli.commands import COMMANDS
from appmode.cli.live_view import add_foxglove, live_view
from appmode.cli.options import (
    DAY,
    Subparsers,
    add_chassis,
    add_profile,
    file_name,
    number_type,
)
from appmode.errors import AppmodeError


def register(sub: Subparsers) -> argparse.ArgumentParser:
    replay = sub.add_parser(
        "replay",
        help=COMMANDS["replay"],
        description="Play the host's lines ('>', driving a board) or the board's lines ('<', "
        "feeding an app) to a port, each at its time from the start. As the host the replay "
        "ends with Z. With --foxglove and no --to, both sides are played to the viewer.",
    )
    replay.add_argument("file", type=file_name, metavar="FILE", help="the transcript")
    replay.add_argument(
        "--to",
        metavar="URL",
        help="where to play it; with --side board, 'pty' makes a new pseudo-terminal for an "
        "app to open (its path is printed; the replay starts when the app sends something)",
    )
    replay.add_argument(
        "--side",
        choices=("host", "board"),
        default="host",
        help="which side to play (default: host)",
    )
    replay.add_argument(
        "--speed",
        type=number_type(0.001, 1000),
        default=1.0,
        metavar="X",
        help="time factor: 2 plays twice as fast (default 1)",
    )
    replay.add_argument(
        "--loop",
        type=number_type(1, 1e6, whole=True),
        default=1,
        metavar="N",
        help="play it N times (default 1)",
    )
    replay.add_argument(
        "--gap",
        type=number_type(0, DAY),
        default=0.0,
        metavar="S",
        help="make every pause between two lines at least S seconds",
    )
    replay.add_argument(
        "--skip",
        type=number_type(0, DAY, low_open=True),
        metavar="S",
        help="shorten every pause longer than S seconds to S",
    )
    replay.add_argument(
        "-v", "--verbose", action="store_true", help="print each line as it is played"
    )
    add_profile(replay, default=None, unset="the transcript's @board profile=…, else sheet")
    add_chassis(replay, "play the transcript's chassis lines (c> or c<) to a chassis port")
    add_foxglove(replay, "the transcript")
    return replay


def run(args: argparse.Namespace) -> int:
    from appmode.board.profiles import profile_named
    from appmode.line.wire import APP, CHASSIS
    from appmode.transcript.dump import needs_of
    from appmode.transcript.replay import run_replay

    if args.side == "host" and args.to == "pty":
        raise AppmodeError(
            "replay --to pty plays the board's side to an app: add --side board (to drive "
            "a board on a pty, serve it with appmode board and replay to its port)"
        )
    if args.to is None and args.foxglove is None:
        raise AppmodeError("replay needs --to URL (a port to play to), --foxglove PORT, or both")
    given = profile_named(args.profile) if args.profile else None  # a file @board may name
    layout = (given or needs_of(args.file, lambda text: None).profile).a_layout
    with live_view(args.foxglove, layout) as view:
        return run_replay(
            args.file,
            args.to,
            args.side,
            args.speed,
            args.loop,
            gap=args.gap,
            skip=args.skip,
            verbose=args.verbose,
            view=view,
            port=CHASSIS if args.chassis else APP,
        )
