"""`appmode plot`: draw a transcript's telemetry (needs matplotlib)."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_profile, file_name


def register(sub: Subparsers) -> argparse.ArgumentParser:
    plot = sub.add_parser(
        "plot",
        help=COMMANDS["plot"],
        description="Draw velocities, attitude and battery over time, with the commands "
        "marked, to a PNG. Needs matplotlib: pip install matplotlib.",
    )
    plot.add_argument("file", type=file_name, metavar="FILE", help="the transcript")
    plot.add_argument(
        "-o", "--output", required=True, type=file_name, metavar="PNG", help="the image to write"
    )
    add_profile(plot, default=None, unset="the transcript's @board profile=…, else sheet")
    return plot


def run(args: argparse.Namespace) -> int:
    from appmode.transcript.plot import run_plot

    run_plot(args.file, args.output, args.profile)
    print(f"wrote {args.output}", file=sys.stderr)
    return 0
