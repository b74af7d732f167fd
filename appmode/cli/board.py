"""`appmode board`: serve the simulated board on a pseudo-terminal, TCP or a serial port."""

from __future__ import annotations

import argparse

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_profile, add_record, file_name, number_type
from appmode.protocol.params import DRIVE_NAMES


def register(sub: Subparsers) -> argparse.ArgumentParser:
    board = sub.add_parser(
        "board",
        help=COMMANDS["board"],
        description="Serve the simulated board so that any serial program (the phone app "
        "through a Bluetooth module, miniterm, appmode itself) can talk to it. Prints "
        "'port: URL' (the APP port, UART3 at 9600 bps) and 'uart2: URL' (the control "
        "port, UART2 at 115200 bps, docs/protocol.md §8) for clients to open, then logs "
        "what it receives, port by port, until Ctrl-C.",
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
    where2 = board.add_mutually_exclusive_group()
    where2.add_argument(
        "--listen2",
        metavar="HOST:PORT",
        help="serve UART2, the control port, on TCP (default: a second pseudo-terminal)",
    )
    where2.add_argument(
        "--port2",
        metavar="DEV",
        help="serve UART2 on a real serial port (?baud=N to change 115200)",
    )
    board.add_argument(
        "--baud",
        type=number_type(300, 4_000_000, whole=True),
        metavar="N",
        help="the APP port's bit rate (default 9600): a car whose Bluetooth module is set "
        "to another rate. It paces the port; on a pty, a client that opens it at another "
        "rate reads garbled bytes, as from a real UART (the UART2 pty likewise at 115200)",
    )
    board.add_argument(
        "--count",
        type=number_type(1, 1000, whole=True),
        default=1,
        metavar="N",
        help="serve N boards, each on its own pty, from this one process (default 1)",
    )
    board.add_argument(
        "--link",
        type=file_name,
        metavar="PATH",
        help="with --pty: keep a symlink PATH to the pty, so clients find a restarted board "
        "at the same path",
    )
    add_profile(
        board,
        "the board's behaviour: sheet (the vendor's sheet, the default) or "
        "minibalance (the reference firmware as measured, docs/protocol.md §13)",
    )
    board.add_argument(
        "--drive", choices=DRIVE_NAMES, help="drive type (default: the saved one, else omni)"
    )
    board.add_argument(
        "--flash",
        type=file_name,
        metavar="FILE",
        help="keep saved parameters in this JSON file (default: in memory)",
    )
    board.add_argument(
        "--no-pace",
        action="store_true",
        help="send as fast as the link takes, not at the line rates (9600 bps on the APP "
        "port, 115200 on UART2)",
    )
    add_record(board)
    board.add_argument(
        "--quiet", "-q", action="store_true", help="do not log what the board receives"
    )
    return board


def run(args: argparse.Namespace) -> int:
    from appmode.ports.serve import run_board

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
        profile=args.profile,
        listen2=args.listen2,
        device2=args.port2,
        baud=args.baud,
    )
