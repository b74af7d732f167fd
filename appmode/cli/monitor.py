"""`appmode monitor`: print decoded records as they arrive."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from contextlib import ExitStack
from typing import TYPE_CHECKING, TextIO

from appmode.cli.commands import COMMANDS
from appmode.cli.live_view import add_foxglove
from appmode.cli.options import (
    DAY,
    ON_A_BOARD,
    Subparsers,
    add_chassis,
    add_profile,
    add_record,
    add_uart2,
    add_url,
    board_choice,
    number_type,
)
from appmode.errors import AppmodeError
from appmode.protocol import app
from appmode.text import counted

if TYPE_CHECKING:
    from appmode.cli.options import Address
    from appmode.host.app.client import Event
    from appmode.ports.choice import BoardChoice


def register(sub: Subparsers) -> argparse.ArgumentParser:
    mon = sub.add_parser(
        "monitor",
        help=COMMANDS["monitor"],
        description="Print each record as it arrives (and each undecodable run of bytes), "
        "until Ctrl-C. Link losses are reported on stderr and the link is reopened. A "
        "monitor only listens: it writes nothing to the port unless --stop-on-exit.",
    )
    add_url(mon)
    mon.add_argument("--json", action="store_true", help="print JSON Lines")
    add_profile(mon, ON_A_BOARD, default=None)
    add_limits(mon, "show and count only these")
    mon.add_argument(
        "--stop-on-exit",
        action="store_true",
        help="send Z when the monitor ends (it sends nothing otherwise)",
    )
    add_uart2(mon, "print the replies and encoder reports of the board's control port")
    add_chassis(mon, "print the status frames of the board's chassis port")
    add_record(mon)
    add_foxglove(mon, "the records")
    return mon


def add_limits(parser: argparse.ArgumentParser, filtering: str) -> None:
    """--duration, --count and --filter, as monitor and record share them."""
    parser.add_argument(
        "--duration",
        type=number_type(0, DAY, low_open=True),
        metavar="SECONDS",
        help="stop after this long",
    )
    parser.add_argument(
        "--count",
        type=number_type(1, 1e9, whole=True),
        metavar="N",
        help="stop after N records (of the --filter kinds; undecodable bytes do not count)",
    )
    parser.add_argument(
        "--filter",
        type=parse_kinds,
        metavar="KINDS",
        help=f"{filtering}: record letters and 'errors', e.g. A,B or C",
    )


def run(args: argparse.Namespace) -> int:
    from appmode.line.wire import APP, CHASSIS, UART2

    choice = board_choice(args)
    monitors = {APP: _on_app, UART2: _on_control, CHASSIS: _on_chassis}
    return monitors[choice.port](choice, args)


def _on_control(choice: BoardChoice, args: argparse.Namespace) -> int:
    from appmode.cli import uart2

    return _on_frames(choice, args, uart2.run_monitor, "--uart2")


def _on_chassis(choice: BoardChoice, args: argparse.Namespace) -> int:
    from appmode.cli import chassis

    return _on_frames(choice, args, chassis.run_monitor, "--chassis")


def _on_frames(
    choice: BoardChoice, args: argparse.Namespace, run: Callable[..., int], flag: str
) -> int:
    """A port of binary frames, monitored by `run` with the command line's options."""
    if args.filter is not None:
        raise AppmodeError(f"--filter picks APP records: not with {flag}")
    return run(
        choice,
        as_json=args.json,
        duration=args.duration,
        count=args.count,
        record=args.record,
        out=sys.stdout,
        stop_on_exit=args.stop_on_exit,
        foxglove=args.foxglove,
    )


def _on_app(choice: BoardChoice, args: argparse.Namespace) -> int:
    return run_monitor(
        choice,
        as_json=args.json,
        duration=args.duration,
        count=args.count,
        record=args.record,
        stop_on_exit=args.stop_on_exit,
        kinds=args.filter,
        out=sys.stdout,
        foxglove=args.foxglove,
    )


def run_monitor(
    choice: BoardChoice,
    *,
    as_json: bool,
    duration: float | None,
    count: int | None,
    record: str | None,
    out: TextIO | None,
    stop_on_exit: bool = False,
    kinds: frozenset[str] | None = None,
    name: str = "monitor",
    foxglove: Address | None = None,
) -> int:
    """Print records as they arrive (of `kinds` only, if given: record letters or
    "errors"), until interrupted, `duration` or `count` of them; `out` None prints none
    (`appmode record`)."""
    from appmode.cli.hostio import open_host, show, until_count
    from appmode.cli.live_view import live_view

    with ExitStack() as stack:
        view = stack.enter_context(
            live_view(foxglove, choice.profile.a_layout, drive_type=choice.known_drive)
        )
        host = open_host(stack, choice, record, stop_on_close=stop_on_exit, view=view)
        url = choice.target
        doing = f"recording {url} to {record}" if out is None else f"monitoring {url}"
        sys.stderr.write(f"{doing} (Ctrl-C to stop)\n")  # one write: the FIFO's note is another
        sys.stderr.flush()
        wanted = (e for e in host.events(duration) if kinds is None or _kind(e) in kinds)
        try:
            for event in until_count(wanted, _is_record, count):
                if out is not None:
                    show(host, event, out, as_json)
        finally:
            stats = host.state.stats
            skipped = f" ({stats.skipped} before the first record)" if stats.skipped else ""
            print(
                f"{name}: {counted(stats.records, 'record')}, {counted(stats.errors, 'error')}, "
                f"{stats.bytes_in} bytes{skipped} in {host.now():.1f} s",
                file=sys.stderr,
            )
    return 0


def parse_kinds(text: str) -> frozenset[str]:
    """`--filter A,B,errors`: record letters, and `errors` for what did not decode."""
    kinds = frozenset(k.strip().upper() for k in text.split(",") if k.strip())
    bad = [k for k in kinds if not (len(k) == 1 and k.isalpha() and k.isascii()) and k != "ERRORS"]
    if bad or not kinds:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected record letters and 'errors', e.g. A,B or C,errors"
        )
    return kinds


def _is_record(event: Event) -> bool:
    return isinstance(event, app.RECORDS)


def _kind(event: Event) -> str:
    if isinstance(event, app.RECORDS):
        return event.letter
    if isinstance(event, app.ERRORS):
        return "ERRORS"
    return "LINK"  # link changes always show
