"""`appmode plot`: draw a transcript's telemetry (needs matplotlib)."""

from __future__ import annotations

import argparse
import os
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_chassis, add_profile, file_name


def register(sub: Subparsers) -> argparse.ArgumentParser:
    plot = sub.add_parser(
        "plot",
        help=COMMANDS["plot"],
        description="Draw velocities, attitude and battery over time, with the commands "
        "marked, to a PNG. Needs matplotlib: pip install matplotlib.",
    )
    plot.add_argument("file", type=file_name, metavar="FILE", help="the transcript")
    plot.add_argument(
        "-o",
        "--output",
        type=file_name,
        metavar="PNG",
        help="the image to write (default: FILE's name with .png, beside it, if no such "
        "file is there yet)",
    )
    add_profile(plot, default=None, unset="the transcript's @board profile=…, else sheet")
    add_chassis(plot, "draw the chassis port's status (velocity, IMU, battery in SI)")
    return plot


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from appmode.errors import AppmodeError
    from appmode.transcript.plot import run_plot

    output = args.output
    if output is None:
        output = str(Path(args.file).with_suffix(".png"))
        if os.path.lexists(output):  # a file of the user's that they did not name
            raise AppmodeError(f"{output} is already there: name the image with -o PNG")
    run_plot(args.file, output, args.profile, chassis_only=args.chassis)
    print(f"wrote {output}", file=sys.stderr)
    return 0
