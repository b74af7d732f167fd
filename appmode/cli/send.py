"""`appmode send`: send letters and frames to a board and print what comes back."""

from __future__ import annotations

import argparse
import sys
from contextlib import ExitStack
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
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
from appmode.host.token_help import APP_TOKENS, CHASSIS_TOKENS, CONTROL_TOKENS

if TYPE_CHECKING:  # the rest is imported when the command runs: start-up stays short
    from typing import TextIO

    from appmode.ports.choice import BoardChoice


def register(sub: Subparsers) -> argparse.ArgumentParser:
    send = sub.add_parser(
        "send",
        help=COMMANDS["send"],
        description=f"Send tokens in order and print the records that come back: "
        f"{APP_TOKENS}. Z is always sent last, so the car is never left moving.",
    )
    add_url(send)
    send.add_argument("tokens", nargs="+", metavar="TOKEN", help="what to send")
    send.add_argument(
        "--listen",
        type=number_type(0, DAY),
        default=0.3,
        metavar="SECONDS",
        help="how long to print replies after the last token (default 0.3)",
    )
    send.add_argument(
        "--raw", action="store_true", help="send frames even if the board would reject them"
    )
    send.add_argument("--json", action="store_true", help="print JSON Lines")
    add_uart2(send, "send over the board's control port; " + CONTROL_TOKENS)
    send.add_argument(
        "--no-report",
        action="store_true",
        help="with --uart2: leave the encoder report as it is (it is on for the session)",
    )
    add_chassis(send, "send over the board's chassis port; " + CHASSIS_TOKENS)
    add_profile(send, ON_A_BOARD, default=None)
    add_record(send)
    return send


def run(args: argparse.Namespace) -> int:
    from appmode.line.wire import APP, CHASSIS, UART2

    choice = board_choice(args)
    return {APP: _on_app, UART2: _on_control, CHASSIS: _on_chassis}[choice.port](choice, args)


def _on_chassis(choice: BoardChoice, args: argparse.Namespace) -> int:
    from appmode.cli import chassis

    if args.raw or args.no_report:
        raise AppmodeError(
            "--raw and --no-report are the APP and control ports': not with --chassis"
        )
    return chassis.run_send(
        choice,
        args.tokens,
        listen=args.listen,
        as_json=args.json,
        record=args.record,
        out=sys.stdout,
    )


def _on_app(choice: BoardChoice, args: argparse.Namespace) -> int:
    return run_send(
        choice,
        args.tokens,
        listen=args.listen,
        raw=args.raw,
        as_json=args.json,
        record=args.record,
        out=sys.stdout,
    )


def _on_control(choice: BoardChoice, args: argparse.Namespace) -> int:
    from appmode.cli import uart2

    return uart2.run_send(
        choice,
        args.tokens,
        listen=args.listen,
        report=not args.no_report,
        as_json=args.json,
        record=args.record,
        out=sys.stdout,
    )


def run_send(
    choice: BoardChoice,
    tokens: list[str],
    *,
    listen: float,
    raw: bool,
    as_json: bool,
    record: str | None,
    out: TextIO,
) -> int:
    """Send the tokens in order, printing what comes back; `Z` is always sent last,
    confirmed on the board's A records (the board's profile says what else stops it)."""
    from appmode.cli.hostio import close_host, open_host, show
    from appmode.host.app.tokens import parse_token
    from appmode.host.waits import Wait
    from appmode.protocol.app_decoders import HostDecoder
    from appmode.protocol.render import describe, line

    steps = [parse_token(token, raw) for token in tokens]  # all checked before sending
    with ExitStack() as stack:
        host = open_host(stack, choice, record, confirm_stop=True)
        for step in steps:
            if isinstance(step, Wait):
                for event in host.events(step.seconds):
                    show(host, event, out, as_json)
                continue
            host.send(step)
            if not as_json:
                text = ", ".join(describe(e) for e in HostDecoder().feed(step))
                out.write(line(host.now(), ">", step, text) + "\n")
            for event in host.poll(0):
                show(host, event, out, as_json)
        for event in host.events(listen):
            show(host, event, out, as_json)
        stop_text = host.state.end.stop_text  # what the stop below will do
        sent_at = host.now()  # the stop goes first; confirming it takes a while after
        stop = close_host(host)
        if stop is None:
            return 1
        if not as_json:
            out.write(line(sent_at, ">", stop, stop_text) + "\n")
    return 0
