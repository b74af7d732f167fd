"""`appmode web`: drive and tune a car from a browser: the page appmode serves."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
from appmode.cli.drive import add_board
from appmode.cli.live_view import LiveViews
from appmode.cli.options import (
    Subparsers,
    add_host_id,
    board_choice,
    endpoint,
    listen,
    target,
)
from appmode.errors import AppmodeError

if TYPE_CHECKING:
    import ssl

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
        type=listen("--listen"),
        metavar="HOST:PORT",
        default=DEFAULT_LISTEN,
        help=f"where to serve the page (default {DEFAULT_LISTEN}; port 0 picks a free one). "
        "On any address but loopback (0.0.0.0: every network of this machine, for a "
        "phone on the same Wi-Fi) the page is served over HTTPS, which a phone's tilt "
        "sensor needs: with appmode's own certificate, made on first use, unless --cert "
        "and --key give yours",
    )
    web.add_argument(
        "--fleet",
        action="store_true",
        help="show every car shared with appmode share that the key opens, as cards with "
        "a stop-all button; tapping a card drives that car (needs the net extra)",
    )
    web.add_argument(
        "--connect",
        action="append",
        type=endpoint,
        default=[],
        metavar="ENDPOINT",
        help="with --fleet: a share or a router to reach the cars through, tcp/HOST:PORT "
        "(default: scout this LAN)",
    )
    web.add_argument(
        "--fleet-key", metavar="KEY", help="with --fleet: the cars' key (default: this machine's)"
    )
    add_host_id(web, "--fleet-id")
    web.add_argument("--cert", metavar="FILE", help="serve HTTPS with this PEM certificate")
    web.add_argument("--key", metavar="FILE", help="the private key of --cert (PEM)")
    return web


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from appmode.session.opener import open_session
    from appmode.web.access import is_loopback
    from appmode.web.bridge import driving

    try:
        from appmode.web import certificate
        from appmode.web.server import serve_web
    except ImportError:
        raise AppmodeError(
            "appmode web needs aiohttp (and cryptography for HTTPS): pip install aiohttp "
            "cryptography (or, in a checkout of appmode, pip install '.[web]')"
        ) from None
    if (args.cert is None) != (args.key is None):
        raise AppmodeError("--cert and --key go together: the certificate and its key")
    host, port = args.listen
    names = [n for n in certificate.machine_names(host) if not is_loopback(n)]
    addresses = sorted(names, key=lambda name: (":" in name, not name[0].isdigit(), name))
    tls = fingerprint = None
    if args.cert is not None:
        tls = certificate.server_context(Path(args.cert), Path(args.key))
    elif not is_loopback(host):
        cert, key = certificate.own_certificate(certificate.machine_names(host))
        tls, fingerprint = certificate.server_context(cert, key), certificate.fingerprint(cert)
    if args.fleet:
        return _serve_fleet(args, host, port, tls, tuple(addresses), fingerprint)
    if args.connect or args.fleet_key is not None or args.host_id is not None:
        raise AppmodeError("--connect, --fleet-key and --fleet-id go with --fleet")
    with LiveViews(args.foxglove, args.foxglove_drive) as views:
        choice = board_choice(args)
        session = open_session(choice, driving(), record=args.record, view=views.make)
        return serve_web(session, host, port, tls, tuple(addresses), fingerprint)


def _serve_fleet(
    args: argparse.Namespace,
    host: str,
    port: int,
    tls: ssl.SSLContext | None,
    addresses: tuple[str, ...],
    fingerprint: str | None,
) -> int:
    """The fleet page: the cars the key opens; a car chosen there driven as URL is."""
    from appmode.cli.share import kept_key
    from appmode.net.config import close_session, open_session, zenoh_module
    from appmode.net.signature import Trust
    from appmode.ports.target import shared_car
    from appmode.session.base import BaseSession
    from appmode.session.opener import open_session as open_car_session
    from appmode.web.bridge import driving
    from appmode.web.fleet import Fleet
    from appmode.web.server import serve_web

    if args.url2 is not None or args.url != target("sim://") or args.uart2 or args.record:
        raise AppmodeError(
            "--fleet shows the shared cars: give no URL, --uart2 or --record with it"
        )
    zenoh_module()
    connect = tuple(args.connect)
    key = args.fleet_key or kept_key()
    trust = Trust(key, args.host_id)
    zenoh = open_session("client", key, connect=connect, scout=not connect)

    def open_car(name: str) -> BaseSession:
        choice = board_choice(args, url=shared_car(name, connect, key, trust.id))
        session = open_car_session(choice, driving())
        session.start()
        return session

    try:
        return serve_web(
            None, host, port, tls, addresses, fingerprint, fleet=Fleet(zenoh, trust, open_car)
        )
    finally:
        close_session(zenoh)
