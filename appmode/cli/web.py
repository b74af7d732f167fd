"""`appmode web`: drive and tune a car from a browser: the page appmode serves."""

from __future__ import annotations

import argparse

from appmode.cli.commands import COMMANDS
from appmode.cli.drive import add_board
from appmode.cli.options import Subparsers
from appmode.errors import AppmodeError

DEFAULT_LISTEN = "127.0.0.1:8080"


def register(sub: Subparsers) -> argparse.ArgumentParser:
    web = sub.add_parser(
        "web",
        help=COMMANDS["web"],
        description="Serve a page that drives the car from a browser: a direction pad "
        "(hold to drive, lift to stop), the status, and a command line for the "
        "parameters. With no URL it drives the embedded simulated board. It prints the "
        "address to open, with a token that admits only you; Ctrl-C stops the car and the "
        "server. A direction held on the page lasts only while the page says so: a closed "
        "page, a hidden tab or a lost network stops the car within 0.25 s.",
    )
    add_board(web)
    web.add_argument(
        "--listen",
        metavar="HOST:PORT",
        default=DEFAULT_LISTEN,
        help=f"where to serve the page (default {DEFAULT_LISTEN}; port 0 picks a free one). "
        "Only this machine's loopback addresses for now: a phone on the network needs "
        "HTTPS for its sensors, which appmode web does not serve yet",
    )
    return web


def run(args: argparse.Namespace) -> int:
    from appmode.cli.drive import make_session
    from appmode.ports.endpoints import parse_listen
    from appmode.web.access import is_loopback
    from appmode.web.bridge import driving

    try:
        from appmode.web.server import serve_web
    except ImportError:
        raise AppmodeError(
            "appmode web needs aiohttp: pip install aiohttp (or, in a checkout of appmode, "
            "pip install '.[web]')"
        ) from None

    host, port = parse_listen(args.listen)
    if not is_loopback(host):
        raise AppmodeError(
            f"--listen {args.listen}: appmode web serves this machine only (127.0.0.1, "
            "localhost or ::1) until it serves HTTPS; from a phone, forward the port "
            "(ssh -L 8080:127.0.0.1:8080 THIS_MACHINE) or drive with appmode drive"
        )
    return serve_web(make_session(args, driving(), None), host, port)
