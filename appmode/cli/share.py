"""`appmode share`: put a car this machine reaches on the network (Eclipse Zenoh), for
other machines to drive, watch and record — this machine stays its stop authority."""

from __future__ import annotations

import argparse
import os
import secrets
import socket
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import quote

from appmode.cli.commands import COMMANDS
from appmode.cli.options import (
    HOLDS,
    Subparsers,
    add_car,
    add_chassis,
    add_profile,
    board_choice,
    endpoint,
    listening_endpoint,
)
from appmode.errors import AppmodeError, install_line

if TYPE_CHECKING:
    import zenoh

    from appmode.net.beats import BeatListener
    from appmode.net.config import Tls
    from appmode.net.share import Share
    from appmode.ports.choice import BoardChoice

DEFAULT_LISTEN = "tcp/127.0.0.1:7450"
KEY_FILE = "share.key"
"""The share's key, kept in appmode's data folder (made on first use, the user's
alone): the URL another machine pasted stays good from one share to the next."""
HOST_KEY_FILE = "share.host-key"
"""The room's host key, kept beside it: shares and routers that hold it speak for cars
(`net.roles`); a client's key does not. Copy it to each car's host and router of a room."""
KEY_BYTES = 18
"""A new key's random bytes (24 characters of URL-safe text)."""


def register(sub: Subparsers) -> argparse.ArgumentParser:
    share = sub.add_parser(
        "share",
        help=COMMANDS["share"],
        description="Share the car at URL (its APP port; URL2 its control port; sim:// both "
        "ports of the simulated board) on the network as NAME, over Eclipse Zenoh: every "
        "command on another machine then takes the zenoh:// URL this prints, as it takes "
        "a local port. This machine stays the car's stop authority: when the remote "
        "driver's heartbeats stop (its process killed, its machine asleep, the network "
        "cut) it stops the car within half a second, and when share ends it stops the "
        "car. Only a client with the key gets in (Zenoh's user-password authentication; "
        "--tls also encrypts). Needs the net extra.",
    )
    add_car(share)
    share.add_argument("--name", required=True, type=car_name, help="what the car is called")
    share.add_argument(
        "--listen",
        type=listening_endpoint,
        metavar="tcp/ADDR:PORT",
        default=DEFAULT_LISTEN,
        help=f"where other machines connect (default {DEFAULT_LISTEN}: this machine only; "
        "tcp/0.0.0.0:PORT for the LAN, where the car is also found by scouting; port 0 "
        "picks a free one)",
    )
    share.add_argument(
        "--connect",
        action="append",
        type=endpoint,
        default=[],
        metavar="ENDPOINT",
        help="connect to a Zenoh router, or to another share (shares route for each other): "
        "tcp/HOST:PORT; may be given more than once",
    )
    share.add_argument(
        "--key",
        help="the key a client needs (any printable text; default: appmode's own, made on "
        "first use and kept in its data folder)",
    )
    add_host_key(share)
    share.add_argument(
        "--tls",
        action="store_true",
        help="listen on tls/ instead of tcp/, with appmode's own certificate: the key is "
        "checked and everything encrypted (a client needs the certificate: ca= in the URL)",
    )
    add_profile(share, f"the car's profile, {HOLDS}", default=None)
    add_chassis(share, "share a WHEELTEC car's chassis port (clients open it with port=chassis)")
    return share


def add_host_key(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--host-key",
        metavar="KEY",
        help="the room's host key, which only its cars' hosts and routers hold (clients "
        "cannot speak for a car without it); default: appmode's own, made on first use "
        f"and kept in its data folder ({HOST_KEY_FILE}): copy it to every share and router "
        "that connect to each other",
    )


def host_key(args: argparse.Namespace) -> str:
    """The host key given, else this machine's own."""
    key: str = args.host_key if args.host_key is not None else kept_key(HOST_KEY_FILE)
    if not key or not key.isprintable():
        raise AppmodeError("--host-key: give printable text, the same on every host of a room")
    return key


def car_name(text: str) -> str:
    from appmode.ports.remote import NAME

    if not NAME.fullmatch(text):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a car's name: letters, digits, - and _ (at most 64), e.g. car-1"
        )
    return text


@dataclass(frozen=True, slots=True)
class Sharing:
    """What a share is told, each part checked once: the car's name, where it listens
    (and the address in that) and connects, its keys, its TLS."""

    name: str
    listen: str
    host: str
    connect: tuple[str, ...]
    key: str
    host_key: str
    tls: Tls | None

    @property
    def everywhere(self) -> bool:
        """It listens on every network of the machine."""
        return self.host in ("0.0.0.0", "::")


def run(args: argparse.Namespace) -> int:
    from appmode.net.config import free_port, zenoh_module
    from appmode.net.zenoh_log import zenoh_refusals

    zenoh_module()
    choice = board_choice(args, both=True)
    key = args.key if args.key is not None else kept_key()
    if not key or not key.isprintable():
        raise AppmodeError("--key: give printable text (a key is what a client pastes)")
    listen = free_port(args.listen.replace("tcp/", "tls/", 1) if args.tls else args.listen)
    host = listen.split("/", 1)[1].rsplit(":", 1)[0].strip("[]")
    sharing = Sharing(
        args.name,
        listen,
        host,
        tuple(args.connect),
        key,
        host_key(args),
        _tls(host) if args.tls else None,
    )
    with zenoh_refusals(_log):
        return _serve(sharing, choice)


def _serve(sharing: Sharing, choice: BoardChoice) -> int:
    from appmode.host import signals
    from appmode.net.config import close_session, open_session
    from appmode.net.share import Share
    from appmode.net.signature import Signer

    listen, everywhere = sharing.listen, sharing.everywhere
    session = open_session(
        "peer",
        sharing.key,
        listen=(listen,),
        connect=sharing.connect,
        scout=everywhere,
        tls=sharing.tls,
        host_key=sharing.host_key,
    )
    shared: Share | None = None
    beats: list[BeatListener] = []
    try:
        signer = Signer(sharing.host_key)
        shared = Share(session, sharing.name, choice, _log, signer)
        beats = _beats(sharing, shared)
        _joined(session, sharing.connect)
        print(remote_url(sharing, signer.id), flush=True)
        _announce(sharing.host, listen, everywhere)
        ended = _Ended()
        with signals.diverted(ended.set):
            shared.run(ended.is_set)
    finally:
        for listener in beats:
            listener.close()
        if shared is not None:
            shared.close()
        close_session(session)
    return 0


def _joined(session: zenoh.Session, connect: tuple[str, ...]) -> None:
    """Say when the routers or shares `--connect` named have not let this one in (the
    share started meanwhile: by now a refusal has come): Zenoh tries them again."""
    info = session.info
    if connect and not [*info.routers_zid(), *info.peers_zid()]:
        _log(
            f"not joined {', '.join(connect)}: nothing listens there, or it refused this "
            "share's host key (every share and router that connect to each other need one "
            "--host-key); trying again"
        )


def _beats(sharing: Sharing, shared: Share) -> list[BeatListener]:
    """The driver's heartbeats on UDP (`net.beats`): at the port number the share
    listens on, and relayed by each router it connects to; where that port is taken,
    said, they come on Zenoh alone."""
    from appmode.net.beats import BeatListener, RelayedBeats, address_of

    name, beat = shared.keys.name, shared.beat
    listeners: list[BeatListener] = []
    address = address_of(sharing.listen)
    if address is not None:
        try:
            listeners.append(BeatListener.on(*address, name, beat))
        except OSError as exc:
            _log(f"heartbeats on UDP port {address[1]}: {exc.strerror}: they come on Zenoh alone")
    for router in filter(None, map(address_of, sharing.connect)):
        try:
            listeners.append(RelayedBeats(router, name, beat, sharing.host_key))
        except OSError as exc:
            _log(f"heartbeats through {router[0]}: {exc.strerror}: they come on Zenoh alone")
    return listeners


class _Ended:
    """Set by an ending signal (a flag: safe in a signal handler, unlike a lock)."""

    def __init__(self) -> None:
        self._set = False

    def set(self) -> None:
        self._set = True

    def is_set(self) -> bool:
        return self._set


def remote_url(sharing: Sharing, host_id: str) -> str:
    """The URL another machine pastes (this machine's LAN address when it listens on
    all), with the id of the host that signs for the car."""
    endpoint = sharing.listen
    if sharing.everywhere:
        scheme, rest = endpoint.split("/", 1)
        endpoint = f"{scheme}/{_lan_address()}:{rest.rsplit(':', 1)[1]}"
    key = quote(sharing.key, safe="")
    return f"zenoh://{sharing.name}?connect={endpoint}&key={key}&id={host_id}"


def _lan_address() -> str:
    """This machine's first address on a network (not loopback), else its name."""
    try:
        from appmode.web.certificate import lan_addresses

        found = lan_addresses(ipv6=False)
    except ImportError:  # psutil comes with the web extra
        found = []
    return found[0] if found else socket.gethostname()


def kept_key(file: str = KEY_FILE) -> str:
    """appmode's own share key (or host key): made on first use, the user's alone, then
    the same."""
    key = own_key(file)
    if key is None:
        key = secrets.token_urlsafe(KEY_BYTES)
        _write_private(key_path(file), key)
    return key


def key_path(file: str = KEY_FILE) -> Path:
    from appmode.files import data_folder

    return data_folder() / file


def own_key(file: str = KEY_FILE) -> str | None:
    """This machine's share key (or host key), None if it has none (nothing is made)."""
    path = key_path(file)
    try:
        return path.read_text(encoding="utf-8").strip()
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise AppmodeError(f"cannot read the share key {path}: {exc.strerror}") from None


def a_clients_key(given: str | None, command: str) -> str:
    """The key a client command uses: the one given, else this machine's own (a share's
    here); AppmodeError, saying where a key comes from, when there is neither."""
    key = given if given is not None else own_key()
    if key is None:
        raise AppmodeError(
            f"{command}: no key: give the cars' key with --key KEY (the key= part of the "
            f"URL appmode share printed); this machine has shared no car ({key_path()} "
            "does not exist)"
        )
    return key


def _write_private(path: Path, text: str) -> None:
    try:
        path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w", encoding="utf-8") as file:
            file.write(text + "\n")
    except OSError as exc:
        raise AppmodeError(f"cannot keep the share key in {path}: {exc.strerror}") from None


def _tls(host: str) -> Tls:
    """appmode's own certificate for a share's `tls/` listener (its own: the page's is
    another); where it is and its fingerprint said, for the clients' `ca=`."""
    from appmode.net.config import Tls

    try:
        from appmode.web.certificate import fingerprint, grouped, machine_names, own_certificate
    except ImportError:
        raise AppmodeError(
            f"--tls makes a certificate with cryptography: {install_line('web')}"
        ) from None
    cert, key = own_certificate(machine_names(host), server="share")
    lines = "".join(f"\nappmode:   {line}" for line in grouped(fingerprint(cert)))
    print(
        f"appmode: a client needs this share's certificate, {cert}: copy it to the client's "
        f"machine and add &ca=FILE to the URL (its SHA-256 fingerprint is{lines})",
        file=sys.stderr,
    )
    return Tls(certificate=str(cert), private_key=str(key))


def _announce(host: str, listen: str, everywhere: bool) -> None:
    loopback = host in ("127.0.0.1", "::1", "localhost")
    if not loopback:
        print(
            f"appmode: WARNING: the car is shared on {listen}: every device that reaches "
            "this machine there can try to connect; only the key keeps it from driving "
            "the car" + ("" if listen.startswith("tls/") else " (and tcp/ is not encrypted)"),
            file=sys.stderr,
        )
    if everywhere:
        print("appmode: found on this LAN by scouting, too", file=sys.stderr)
    where = (
        "in another program on this machine (--listen tcp/0.0.0.0:7450 shares it on the LAN)"
        if loopback
        else "into appmode on another machine"
    )
    print(
        f"appmode: paste that URL {where}; Ctrl-C stops the car and the share",
        file=sys.stderr,
        flush=True,
    )


def _log(text: str) -> None:
    print(f"share: {text}", file=sys.stderr, flush=True)
