"""`appmode router`: a Zenoh router in this process, for a site with none: shares and
clients on other networks meet at it (`--connect` on both sides)."""

from __future__ import annotations

import argparse
import sys
import time
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, listening_endpoint
from appmode.cli.share import add_host_key

if TYPE_CHECKING:
    from appmode.net.beats import BeatRelay

DEFAULT_LISTEN = "tcp/127.0.0.1:7447"


def register(sub: Subparsers) -> argparse.ArgumentParser:
    router = sub.add_parser(
        "router",
        help=COMMANDS["router"],
        description="Run a Zenoh router (no zenohd needed): appmode share --connect and every "
        "zenoh:// URL's connect= may name it, across networks a LAN's scouting does not "
        "reach. It admits only clients with the key, and holds them to a client's role: only "
        "the cars' hosts, with the room's host key, speak for a car. Needs the net extra.",
    )
    router.add_argument(
        "--listen",
        type=listening_endpoint,
        metavar="tcp/ADDR:PORT",
        default=DEFAULT_LISTEN,
        help=f"where it listens (default {DEFAULT_LISTEN}; tcp/0.0.0.0:7447 for every network)",
    )
    router.add_argument("--key", help="the key (default: this machine's share key)")
    add_host_key(router)
    return router


def run(args: argparse.Namespace) -> int:
    from appmode.cli.share import host_key, kept_key
    from appmode.host import signals
    from appmode.net.config import close_session, free_port, open_session, zenoh_module

    zenoh_module()
    listen = free_port(args.listen)
    key, hosts_key = args.key or kept_key(), host_key(args)
    session = open_session("router", key, listen=(listen,), host_key=hosts_key)
    relay = _relay(listen, hosts_key)
    ended = [False]
    try:
        print(f"router: {listen}", flush=True)
        print("appmode: Ctrl-C stops the router", file=sys.stderr, flush=True)
        with signals.diverted(lambda: ended.__setitem__(0, True)):
            while not ended[0]:
                time.sleep(0.1)
    finally:
        if relay is not None:
            relay.close()
        close_session(session)
    return 0


def _relay(listen: str, hosts_key: str) -> BeatRelay | None:
    """The drivers' heartbeats on UDP, relayed to the cars' hosts (`net.beats`), at the
    port number the router listens on; None, said, when that port is taken."""
    from appmode.net.beats import BeatRelay, address_of

    address = address_of(listen)
    if address is None:
        return None
    try:
        return BeatRelay(*address, hosts_key)
    except OSError as exc:
        print(
            f"appmode: heartbeats on UDP port {address[1]}: {exc.strerror}: they reach the cars "
            "on Zenoh alone",
            file=sys.stderr,
            flush=True,
        )
        return None
