"""The `appmode` command line: argument parsing and dispatch only."""

from __future__ import annotations

import argparse
import os
import signal
import sys
from collections.abc import Callable, Sequence

from . import __version__
from .driving import FIRST_TIMEOUT, REPEAT_TIMEOUT
from .errors import AppmodeError
from .params import DRIVE_NAMES, PARAMS, DriveType

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


def _cmd_drive(args: argparse.Namespace) -> int:
    from .console import run_drive
    from .driving import HoldToDrive
    from .session import Session

    interactive = sys.stdin.isatty() and sys.stdout.isatty()
    driving = HoldToDrive(args.hold_first, args.hold_repeat, args.latched or not interactive)
    session = Session(
        args.url, driving, args.record, on_message=None if interactive else _print_message
    )
    return run_drive(session, interactive, sys.stdin, sys.stdout)


def _print_message(text: str) -> None:
    print(text, flush=True)


def _cmd_board(args: argparse.Namespace) -> int:
    from .serve import run_board

    return run_board(
        use_pty=args.pty,
        link=args.link,
        listen=args.listen,
        device=args.port,
        drive=args.drive,
        flash=args.flash,
        pace=not args.no_pace,
        record=args.record,
        quiet=args.quiet,
        count=args.count,
    )


def _cmd_send(args: argparse.Namespace) -> int:
    from .hostcmds import run_send

    return run_send(
        args.url,
        args.tokens,
        listen=args.listen,
        raw=args.raw,
        as_json=args.json,
        record=args.record,
        out=sys.stdout,
    )


def _cmd_params(args: argparse.Namespace) -> int:
    from .hostcmds import run_params

    return run_params(
        args.url, args.set, save=args.save, as_json=args.json, record=args.record, out=sys.stdout
    )


def _cmd_monitor(args: argparse.Namespace) -> int:
    from .hostcmds import run_monitor

    return run_monitor(
        args.url,
        as_json=args.json,
        duration=args.duration,
        count=args.count,
        record=args.record,
        out=sys.stdout,
    )


def _cmd_conform(args: argparse.Namespace) -> int:
    from .conform import run_conform

    return run_conform(args.paths, args.board, args.junit, sys.stdout)


def _cmd_replay(args: argparse.Namespace) -> int:
    from .replay import run_replay

    return run_replay(args.file, args.to, args.side, args.speed, args.loop)


def _cmd_tap(args: argparse.Namespace) -> int:
    from .tap import run_tap

    return run_tap(args.app, args.board, args.record, args.quiet)


def _cmd_dump(args: argparse.Namespace) -> int:
    from .dump import run_dump

    return run_dump(args.file, "json" if args.json else "csv" if args.csv else "text", sys.stdout)


def _cmd_plot(args: argparse.Namespace) -> int:
    from .dump import run_plot

    run_plot(args.file, args.output)
    print(f"wrote {args.output}", file=sys.stderr)
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

    drive = sub.add_parser(
        "drive",
        help="drive and tune a car from the keyboard (the main job)",
        description="The driving console: a live status panel, arrow keys and a 3x3 key grid "
        "(q w e / a s d / z x c) to drive, space to stop, and a command line (:) for "
        "everything else. With no URL it drives the embedded simulated board. When stdin "
        "is not a terminal, commands are read from it line by line (try: help). Whatever "
        "ends the session, the last byte sent is Z.",
    )
    drive.add_argument(
        "url",
        nargs="?",
        default="sim://",
        metavar="URL",
        help="the board (default: sim://, the simulated board); see "
        "'appmode params -h' for URL forms",
    )
    drive.add_argument(
        "--hold-first",
        type=float,
        default=FIRST_TIMEOUT,
        metavar="S",
        help="stop this long after a first key press with no repeat; longer "
        f"than the OS auto-repeat delay (default {FIRST_TIMEOUT})",
    )
    drive.add_argument(
        "--hold-repeat",
        type=float,
        default=REPEAT_TIMEOUT,
        metavar="S",
        help=f"stop this long after the last auto-repeat (default {REPEAT_TIMEOUT})",
    )
    drive.add_argument(
        "--latched", action="store_true", help="a direction stays until stop (key l toggles it)"
    )
    _add_record(drive)
    drive.set_defaults(handler=_cmd_drive)

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

    board = sub.add_parser(
        "board",
        help="serve the simulated board on a pseudo-terminal, TCP or a serial port",
        description="Serve the simulated board so that any serial program (the phone app "
        "through a Bluetooth module, miniterm, appmode itself) can talk to it. Prints "
        "'port: URL' for clients to open, then logs what it receives until Ctrl-C.",
    )
    where = board.add_mutually_exclusive_group()
    where.add_argument(
        "--pty", action="store_true", help="serve on a new pseudo-terminal (the default)"
    )
    where.add_argument(
        "--listen",
        metavar="HOST:PORT",
        help="serve on TCP, one client at a time (host 127.0.0.1 by default; "
        "port 0 picks a free one)",
    )
    where.add_argument(
        "--port",
        metavar="DEV",
        help="serve on a real serial port, e.g. /dev/ttyUSB0 (?baud=N to change 9600)",
    )
    board.add_argument(
        "--count",
        type=int,
        default=1,
        metavar="N",
        help="serve N boards, each on its own pty, from this one process (default 1)",
    )
    board.add_argument(
        "--link",
        metavar="PATH",
        help="with --pty: keep a symlink PATH to the pty, so clients find a restarted board "
        "at the same path",
    )
    board.add_argument(
        "--drive", choices=DRIVE_NAMES, help="drive type (default: the saved one, else omni)"
    )
    board.add_argument(
        "--flash",
        metavar="FILE",
        help="keep saved parameters in this JSON file (default: in memory)",
    )
    board.add_argument(
        "--no-pace",
        action="store_true",
        help="send as fast as the link takes, not at the 9600-bps line rate",
    )
    _add_record(board)
    board.add_argument(
        "--quiet", "-q", action="store_true", help="do not log what the board receives"
    )
    board.set_defaults(handler=_cmd_board)

    send = sub.add_parser(
        "send",
        help="send letters and frames to a board and print what comes back",
        description="Send tokens in order and print the records that come back. Tokens: "
        "letters (A-H drive, I J K pages, Z stop; 'JAZ' sends three), frames ({Q:P}, "
        "{Q:W}, {0:800}), escaped bytes (\\x01) and waits (wait:0.5). Z is always sent "
        "last, so the car is never left moving.",
    )
    _add_url(send)
    send.add_argument("tokens", nargs="+", metavar="TOKEN", help="what to send")
    send.add_argument(
        "--listen",
        type=float,
        default=0.3,
        metavar="SECONDS",
        help="how long to print replies after the last token (default 0.3)",
    )
    send.add_argument(
        "--raw", action="store_true", help="send frames even if the board would reject them"
    )
    send.add_argument("--json", action="store_true", help="print JSON Lines")
    _add_record(send)
    send.set_defaults(handler=_cmd_send)

    prm = sub.add_parser(
        "params",
        help="read, set (verified) and save the nine parameters",
        description="Read the nine parameters; with --set, set each and verify it by reading "
        "back; with --save, save them to the board's flash. Names: "
        + ", ".join(p.name for p in PARAMS)
        + " (or their numbers 0-8).",
    )
    _add_url(prm)
    prm.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a parameter (repeatable), e.g. --set max_speed=800",
    )
    prm.add_argument("--save", action="store_true", help="save to flash ({Q:W})")
    prm.add_argument("--json", action="store_true", help="print one JSON object")
    _add_record(prm)
    prm.set_defaults(handler=_cmd_params)

    mon = sub.add_parser(
        "monitor",
        help="print decoded records as they arrive",
        description="Print each record as it arrives (and each undecodable run of bytes), "
        "until Ctrl-C. Link losses are reported on stderr and the link is reopened.",
    )
    _add_url(mon)
    mon.add_argument("--json", action="store_true", help="print JSON Lines")
    mon.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this long")
    mon.add_argument("--count", type=int, metavar="N", help="stop after N records")
    _add_record(mon)
    mon.set_defaults(handler=_cmd_monitor)

    conform = sub.add_parser(
        "conform",
        help="run transcripts as conformance tests against a board",
        description="Send each transcript's '>' lines at their times and match its '<' lines "
        "against what the board sends ('*' matches any field; unmentioned telemetry is "
        "ignored). Without --board: the embedded simulated board on virtual time (no "
        "waiting). With --board URL: in real time against any board. One line per "
        "transcript; exit status 1 if any fails.",
    )
    conform.add_argument(
        "paths",
        nargs="*",
        metavar="FILE|DIR",
        help="transcripts, or directories searched for *.transcript (default: ./transcripts)",
    )
    conform.add_argument(
        "--board", metavar="URL", help="run in real time against this board instead"
    )
    conform.add_argument("--junit", metavar="FILE", help="also write a JUnit XML report")
    conform.set_defaults(handler=_cmd_conform)

    replay = sub.add_parser(
        "replay",
        help="play one side of a transcript to a port",
        description="Play the host's lines ('>', driving a board) or the board's lines ('<', "
        "feeding an app) to a port, each at its time from the start. As the host the replay "
        "ends with Z.",
    )
    replay.add_argument("file", metavar="FILE", help="the transcript")
    replay.add_argument("--to", required=True, metavar="URL", help="where to play it")
    replay.add_argument(
        "--side",
        choices=("host", "board"),
        default="host",
        help="which side to play (default: host)",
    )
    replay.add_argument(
        "--speed",
        type=float,
        default=1.0,
        metavar="X",
        help="time factor: 2 plays twice as fast (default 1)",
    )
    replay.add_argument(
        "--loop", type=int, default=1, metavar="N", help="play it N times (default 1)"
    )
    replay.set_defaults(handler=_cmd_replay)

    tap = sub.add_parser(
        "tap",
        help="sit between an app and a board, recording both directions",
        description="Forward bytes both ways between the app side and the board side and "
        "record them, timestamped, as a transcript. APP may be 'pty': a new pseudo-terminal "
        "for the app to open (its path is printed as 'port: …'). On exit the board gets Z.",
    )
    tap.add_argument("app", metavar="URL_APP", help="the app's side (or 'pty')")
    tap.add_argument("board", metavar="URL_BOARD", help="the board's side")
    tap.add_argument("--record", required=True, metavar="FILE", help="the transcript to write")
    tap.add_argument("--quiet", "-q", action="store_true", help="no status lines")
    tap.set_defaults(handler=_cmd_tap)

    dump = sub.add_parser(
        "dump",
        help="decode a transcript",
        description="Decode every command and record of a transcript: text, JSON Lines or CSV.",
    )
    dump.add_argument("file", metavar="FILE", help="the transcript")
    fmt = dump.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="JSON Lines")
    fmt.add_argument("--csv", action="store_true", help="CSV with a header row")
    dump.set_defaults(handler=_cmd_dump)

    plot = sub.add_parser(
        "plot",
        help="draw a transcript's telemetry (needs matplotlib)",
        description="Draw velocities, attitude and battery over time, with the commands "
        "marked, to a PNG. Needs the plot extra: pip install 'appmode[plot]'.",
    )
    plot.add_argument("file", metavar="FILE", help="the transcript")
    plot.add_argument("-o", "--output", required=True, metavar="PNG", help="the image to write")
    plot.set_defaults(handler=_cmd_plot)
    return parser


def _add_url(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "url",
        metavar="URL",
        help="the board: /dev/ttyUSB0, /dev/rfcomm0, COM3 (?baud=N), socket://HOST:PORT, "
        "rfc2217://HOST:PORT, loop:// or sim:// (the simulated board)",
    )


def _add_record(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--record", metavar="FILE", help="record the session as a transcript (flushed line by line)"
    )


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    handler: Handler = args.handler
    signal.signal(signal.SIGTERM, _interrupt)
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


def _interrupt(signum: int, frame: object) -> None:
    """SIGTERM ends a command the way Ctrl-C does: cleanly, the car stopped."""
    raise KeyboardInterrupt


if __name__ == "__main__":
    sys.exit(main())
