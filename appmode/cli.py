"""The `appmode` command line: argument parsing and dispatch only."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence

from . import __version__
from .errors import AppmodeError
from .params import DRIVE_NAMES, DriveType

Handler = Callable[[argparse.Namespace], int]


def _cmd_decode(args: argparse.Namespace) -> int:
    from .decoding import run_decode

    if args.file in (None, "-"):
        run_decode(sys.stdin.buffer, sys.stdout, args.source)
        return 0
    try:
        with open(args.file, "rb") as stream:
            run_decode(stream, sys.stdout, args.source)
    except OSError as exc:
        raise AppmodeError(f"cannot read {args.file}: {exc.strerror}") from None
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from .demo import run_demo

    run_demo(sys.stdout, DriveType.from_cli_name(args.drive), None if args.fast else _sleep)
    return 0


def _sleep(seconds: float) -> None:
    import time

    time.sleep(seconds)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="appmode",
        description="Drive, emulate and test robot-car boards that speak the APP protocol "
        "(9600 bps: letters drive, {…} frames read and set parameters).",
    )
    parser.add_argument("--version", action="version", version=f"appmode {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    demo = sub.add_parser(
        "demo",
        help="drive the embedded simulated board through a short route, printing every record",
        description="Boot the simulated board, drive a scripted route (page switch, "
        "directions, stop, parameter set and read) and print each command and decoded record.",
    )
    demo.add_argument(
        "--drive",
        choices=DRIVE_NAMES,
        default="mecanum",
        help="drive type of the simulated board (default: mecanum)",
    )
    demo.add_argument(
        "--fast", action="store_true", help="run on virtual time instead of real time"
    )
    demo.set_defaults(handler=_cmd_demo)

    decode = sub.add_parser(
        "decode",
        help="decode a raw byte stream to JSON Lines",
        description="Decode raw bytes (a capture of the serial line) to JSON Lines: one "
        "object per record or command, and one per undecodable run of bytes.",
    )
    decode.add_argument("file", nargs="?", help="file to read (default: standard input)")
    decode.add_argument(
        "--from",
        dest="source",
        choices=("host", "board"),
        default="board",
        help="who sent the bytes (default: board, i.e. board→host records)",
    )
    decode.set_defaults(handler=_cmd_decode)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    handler: Handler = args.handler
    try:
        return handler(args)
    except AppmodeError as exc:
        print(f"appmode: error: {exc}", file=sys.stderr)
        return 2
    except ValueError as exc:
        print(f"appmode: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
