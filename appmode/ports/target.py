"""A board's URL, parsed once into the `Target` every layer reads (docs/design.md,
"Contracts"): what kind of link it is, a simulated board's options, a device's path and
rate, a Bluetooth module's address. A Target is a value: its `url` is made from its
fields, and another board choice (`with_sim`, `for_uart2`) is a new Target, never text
parsed again."""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from itertools import count
from types import MappingProxyType
from typing import TypeAlias
from urllib.parse import parse_qsl, quote, unquote, urlsplit

from appmode.errors import AppmodeError
from appmode.line.wire import APP, PORTS, UART2
from appmode.ports.radio import BadAddress, BleTarget, BtTarget, parse_ble, parse_bt
from appmode.ports.remote import USAGE as REMOTE_USAGE
from appmode.ports.remote import BadRemote, RemoteTarget, parse_remote
from appmode.ports.schemes import SCHEMES
from appmode.protocol import params

NUMBERED_PTY = re.compile(r"/dev/(pts/\d+|ttys\d+)")
"""A pseudo-terminal named by its number (Linux, macOS)."""
URL_HELP = (
    "use a device path (/dev/ttyUSB0, /dev/rfcomm0, COM3), socket://HOST:PORT, "
    "rfc2217://HOST:PORT, ble://ADDRESS, bt://ADDRESS, zenoh://NAME?connect=…&key=…, "
    "loop:// or sim://"
)
SIM_OPTIONS = ("profile", "drive", "flash", "pace", "baud", "faults", "port", "share")
"""What a sim:// URL may set (ports/sim.py says what each does)."""
SIM_USAGE = (
    "sim://[?profile=sheet|minibalance][&drive=omni|mecanum|diff|diff-gyro][&flash=FILE]"
    "[&pace=1|0][&baud=9600]"
    "[&faults=drop:0.01,corrupt:0.01,…][&port=app|uart2][&share=NAME]"
)

NO_OPTIONS: Mapping[str, str] = MappingProxyType({})
HIDDEN = "…"
KEY_IN_URL = re.compile(r"([?&]key=)[^&#]*")
"""A shared car's key in a URL's text (hidden in every message that quotes it)."""
"""What a URL shows of a shared car's key: messages, pages and recordings never hold it."""


@dataclass(frozen=True, slots=True)
class Target:
    """Where a board is: `parse_target` reads one from a URL, once."""

    scheme: str
    """`sim`, `socket`, `rfc2217`, `loop`, `ble`, `bt`; "" for a device path."""
    address: str = ""
    """What follows `scheme://` up to the options: HOST:PORT, a module's address or name."""
    options: Mapping[str, str] = field(default_factory=lambda: NO_OPTIONS)
    """The URL's options, in their order: a sim:// board's, a module's, pyserial's own."""
    path: str = ""
    """A device's path (without `?baud=`)."""
    baud: int | None = None
    """A device's `?baud=N`."""
    radio: BleTarget | BtTarget | None = None
    """What a `ble://` or `bt://` URL names."""
    remote: RemoteTarget | None = None
    """What a `zenoh://` URL names: a car another machine shares."""

    @property
    def url(self) -> str:
        """The URL as it opens (and as messages show it)."""
        if not self.scheme:
            return self.path if self.baud is None else f"{self.path}?baud={self.baud}"
        query = "&".join(
            f"{k}={HIDDEN if k == 'key' and self.remote else quote(v, safe='/:,[]')}" if v else k
            for k, v in self.options.items()
        )
        return f"{self.scheme}://{self.address}{'?' if query else ''}{query}"

    def __str__(self) -> str:
        return self.url

    @property
    def simulated(self) -> bool:
        return self.scheme == "sim"

    @property
    def network(self) -> bool:
        """A TCP link (socket://, rfc2217://)."""
        scheme = SCHEMES.get(self.scheme)
        return scheme is not None and scheme.network

    @property
    def numbered_pty(self) -> bool:
        """A pseudo-terminal named by its number (/dev/pts/N, /dev/ttysN): once it is gone
        it never comes back, and the number may soon name another program's terminal."""
        return NUMBERED_PTY.fullmatch(self.path) is not None

    @property
    def sim(self) -> Mapping[str, str]:
        """A sim:// URL's options (none for any other URL; a zenoh:// URL's port=)."""
        if self.scheme == "zenoh":
            return {"port": self.options["port"]} if "port" in self.options else NO_OPTIONS
        return self.options if self.simulated else NO_OPTIONS

    @property
    def sim_port(self) -> str:
        """The port a sim:// (or zenoh://) URL opens: `app`, or `uart2` with `port=uart2`."""
        return self.sim.get("port", APP).lower()

    @property
    def profile(self) -> str | None:
        """The profile a sim:// URL names."""
        return self.sim.get("profile")

    @property
    def sim_drive(self) -> str | None:
        """The drive type a sim:// URL names (as the command line spells it)."""
        return self.sim.get("drive")

    def with_sim(self, **options: str | None) -> Target:
        """A sim:// target with `options` where it sets none (a command's `--profile` and
        `--drive` describe the simulated board); one it sets otherwise is an error. Other
        targets as they are."""
        if not self.simulated:
            return self
        added: dict[str, str] = {}
        for name, value in options.items():
            if not value:
                continue
            if name not in self.sim:
                added[name] = value
            elif self.sim[name] != value:
                raise AppmodeError(
                    f"{self.url} sets {name}={self.sim[name]}, and --{name} {value} another: "
                    f"give the {name} once"
                )
        return replace(self, options=_frozen({**self.options, **added})) if added else self

    def for_uart2(self) -> Target:
        """The control port of this target: a sim:// or zenoh:// URL without `port=`
        opens the board's UART2; anything else is the port it names."""
        shared = self.simulated or self.remote is not None
        return self.on_port(UART2) if shared and "port" not in self.options else self

    def on_port(self, port: str) -> Target:
        """The same simulated board's `port` (`app` or `uart2`)."""
        return replace(self, options=_frozen({**self.options, "port": port}))


def board_ports(
    url: Target,
    url2: Target | None,
    *,
    uart2: bool,
    profile: str | None,
    drive: str | None,
) -> tuple[Target, Target | None, bool]:
    """The ports a command opens of the board `url` names: (the port it drives, the
    same board's APP port beside it, whether it drives the control port). With `url2`
    it drives that control port, `url` beside it (two sim:// URLs are one simulated
    board); with `uart2`, `url`'s own control port. A simulated board takes `profile`
    and `drive` (`with_sim`)."""
    board = url.with_sim(profile=profile, drive=drive)
    if url2 is None:
        return (board.for_uart2(), None, True) if uart2 else (board, None, False)
    control = url2.with_sim(profile=profile, drive=drive)
    if not (board.simulated and control.simulated):
        return control, board, True
    options = [
        {k: v for k, v in t.sim.items() if k not in ("port", "share")} for t in (board, control)
    ]
    if options[1] and options[1] != options[0]:
        raise AppmodeError(
            f"{board} and {control} are one simulated board: give its options once, on "
            f"the first URL (appmode drive '{control}' sim://)"
        )
    app, uart2_port = both_ports(board)
    return uart2_port, app, True


def both_ports(target: Target) -> tuple[Target, Target]:
    """A sim:// target's board opened on both its ports: (the APP port, UART2), one board
    (a name it shares, made here unless it names one)."""
    if "share" not in target.sim:
        target = target.with_sim(share=f"board-{os.getpid()}-{next(_SHARES)}")
    app = target if "port" not in target.sim else target.on_port(APP)
    return app, target.on_port(UART2)


_SHARES = count(1)
"""Numbers the names that make two sim:// ports one simulated board, in this process."""


AnyTarget: TypeAlias = "Target | str"
"""What the public API takes for a board (`appmode.Host`, `ControlHost`, `open_link`): a
Target, or a URL it parses once."""


def parse_target(url: str) -> Target:
    """`url` as a Target; AppmodeError says what is wrong and how to write it."""
    if "://" not in url:
        path, baud = parse_device(url)
        return Target("", path=path, baud=baud)
    scheme = url.split("://", 1)[0].lower()
    kind = SCHEMES.get(scheme)
    if kind is None:
        raise AppmodeError(f"unknown URL scheme {scheme + '://'!r} in {url!r}: {URL_HELP}")
    if kind.network:
        _check_address(url, scheme)
    try:
        parts = urlsplit(url)
    except ValueError as exc:  # an unclosed [ in a module's address
        raise AppmodeError(f"{url!r} is not a URL ({exc}): {URL_HELP}") from None
    pairs = parse_qsl(parts.query, keep_blank_values=True)
    options = _frozen(dict(pairs))
    if scheme == "zenoh":
        url = KEY_IN_URL.sub(rf"\1{HIDDEN}", url)  # messages quote it with the key hidden
        twice = sorted({name for name, _ in pairs if [n for n, _ in pairs].count(name) > 1})
        if twice:
            raise AppmodeError(f"{twice[0]}= twice in {url!r}: give each option once")
    if scheme == "sim":
        _check_sim(url, parts.netloc, parts.path, options)
    address = unquote(parts.netloc) + (parts.path if kind.network else "")
    radio: BleTarget | BtTarget | None = None
    remote: RemoteTarget | None = None
    if scheme == "zenoh":
        if parts.path not in ("", "/"):
            raise AppmodeError(f"expected {REMOTE_USAGE}, not {url!r}")
        try:
            remote = parse_remote(address, options, url)
        except BadRemote as exc:
            raise AppmodeError(str(exc)) from None
        _check_port(url, options)
    if kind.radio:
        if parts.path not in ("", "/"):
            address = ""  # a path is no part of a module's address: the usage says so
        try:
            parse = parse_ble if scheme == "ble" else parse_bt
            radio = parse(address, options, url)
        except BadAddress as exc:
            raise AppmodeError(str(exc)) from None
    return Target(scheme, address, options, radio=radio, remote=remote)


def shared_car(name: str, connect: tuple[str, ...], key: str, host_id: str | None) -> Target:
    """The car `name` shared on Zenoh, reached at `connect` (none: by scouting) with
    `key`, signed for by the host of `host_id`: the target its `zenoh://` URL names."""
    options = {"connect": ",".join(connect)} if connect else {}
    if host_id is not None:
        options["id"] = host_id
    remote = RemoteTarget(name, connect, key, host_id=host_id)
    return Target("zenoh", name, _frozen({**options, "key": key}), remote=remote)


def as_target(url: AnyTarget) -> Target:
    """A Target as it is; a URL (the public API's) parsed once."""
    return url if isinstance(url, Target) else parse_target(url)


def _frozen(options: dict[str, str]) -> Mapping[str, str]:
    return MappingProxyType(options)


def _check_sim(url: str, netloc: str, path: str, options: Mapping[str, str]) -> None:
    """A sim:// URL names only its options; a port= is one of the board's two."""
    if netloc or path not in ("", "/"):
        raise AppmodeError(f"expected {SIM_USAGE}, not {url!r}")
    for name in options:
        if name not in SIM_OPTIONS:
            raise AppmodeError(f"unknown sim:// option {name!r}: use {', '.join(SIM_OPTIONS)}")
    _check_port(url, options)


def _check_port(url: str, options: Mapping[str, str]) -> None:
    side = options.get("port", APP).lower()
    if side not in PORTS:
        raise AppmodeError(f"port={side!r} in {url!r}: use {' or '.join(PORTS)}")


def _check_address(url: str, scheme: str) -> None:
    """HOST:PORT must be there before pyserial sees the URL (its messages are Python's)."""
    try:
        parts = urlsplit(url)
        host, port = parts.hostname, parts.port
    except ValueError:  # an unclosed [IPv6 address, a port that is not a number
        host, port = None, None
    if not host or port is None or not 0 < port < 65536:
        raise AppmodeError(
            f"{url!r} needs a host and a port 1–65535: {scheme}://HOST:PORT, "
            f"e.g. {scheme}://127.0.0.1:5000"
        )


def parse_device(url: str, baud: int | None = None) -> tuple[str, int | None]:
    """A device's path and baud rate (`?baud=N`, else `baud`)."""
    path, _, query = url.partition("?")
    if not path:
        raise AppmodeError(f"empty port name in {url!r}: {URL_HELP}")
    for name, value in parse_qsl(query, keep_blank_values=True):
        if name != "baud":
            raise AppmodeError(f"unknown option {name!r} in {url!r}: only ?baud=N is known")
        if not params.whole(value):
            raise AppmodeError(f"bad baud rate {value!r} in {url!r}: use e.g. ?baud=9600")
        baud = int(value.strip())
    return path, baud
