"""A board's URL, parsed once into the `Target` every layer reads: what kind of link it
is, a simulated board's options, a device's path and rate (docs/design.md, "Contracts").
What a `ble://` or `bt://` address says is read by its port when it opens."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from urllib.parse import urlsplit

from serial import SerialException

from appmode.errors import AppmodeError
from appmode.line.wire import APP, UART2
from appmode.protocol import params

SCHEMES = ("sim", "socket", "rfc2217", "loop", "ble", "bt")
NETWORK_SCHEMES = ("socket", "rfc2217")
RADIO_SCHEMES = ("ble", "bt")
NUMBERED_PTY = re.compile(r"/dev/(pts/\d+|ttys\d+)")
"""A pseudo-terminal named by its number (Linux, macOS)."""
URL_HELP = (
    "use a device path (/dev/ttyUSB0, /dev/rfcomm0, COM3), socket://HOST:PORT, "
    "rfc2217://HOST:PORT, ble://ADDRESS, bt://ADDRESS, loop:// or sim://"
)


@dataclass(frozen=True, slots=True)
class Target:
    """Where a board is, as `parse_target` read it from a URL."""

    url: str
    """The URL as opened (and as messages show it)."""
    scheme: str
    """`sim`, `socket`, `rfc2217`, `loop`, `ble`, `bt`; "" for a device path."""
    sim: dict[str, str] = field(default_factory=dict)
    """A sim:// URL's options."""
    path: str = ""
    """A device's path (without `?baud=`)."""
    baud: int | None = None
    """A device's `?baud=N`."""

    def __str__(self) -> str:
        return self.url

    @property
    def simulated(self) -> bool:
        return self.scheme == "sim"

    @property
    def network(self) -> bool:
        """A TCP link (socket://, rfc2217://)."""
        return self.scheme in NETWORK_SCHEMES

    @property
    def radio(self) -> bool:
        """A Bluetooth module reached directly (ble://, bt://)."""
        return self.scheme in RADIO_SCHEMES

    @property
    def numbered_pty(self) -> bool:
        """A pseudo-terminal named by its number (/dev/pts/N, /dev/ttysN): once it is gone
        it never comes back, and the number may soon name another program's terminal."""
        return NUMBERED_PTY.fullmatch(self.path) is not None

    @property
    def sim_port(self) -> str:
        """The port a sim:// URL opens: `app`, or `uart2` with `port=uart2`."""
        return self.sim.get("port", APP).lower()

    @property
    def profile(self) -> str | None:
        """The profile a sim:// URL names."""
        return self.sim.get("profile")

    @property
    def directives(self) -> tuple[str, ...]:
        """Transcript directives that describe a sim:// board, to replay its sessions."""
        needs = " ".join(
            f"{key}={self.sim[key]}" for key in ("profile", "drive") if key in self.sim
        )
        return (f"board {needs}",) if needs else ()

    def with_sim(self, **options: str | None) -> Target:
        """A sim:// target with `options` where it sets none (a command's `--profile` and
        `--drive` describe the simulated board); one it sets otherwise is an error. Other
        targets as they are."""
        if not self.simulated:
            return self
        url = self.url
        for name, value in options.items():
            if not value:
                continue
            if name not in self.sim:
                url += f"{'&' if '?' in url else '?'}{name}={value}"
            elif self.sim[name] != value:
                raise AppmodeError(
                    f"{self.url} sets {name}={self.sim[name]}, and --{name} {value} another: "
                    f"give the {name} once"
                )
        return parse_target(url) if url != self.url else self

    def for_uart2(self) -> Target:
        """The control port of this target: a sim:// URL without `port=` opens the
        simulated board's UART2; anything else is the port it names."""
        return self.with_sim(port=UART2) if self.simulated and "port" not in self.sim else self


def parse_target(url: str) -> Target:
    """`url` as a Target; AppmodeError says what is wrong and how to write it."""
    if "://" not in url:
        path, baud = parse_device(url)
        return Target(url, "", path=path, baud=baud)
    scheme = url.split("://", 1)[0].lower()
    if scheme not in SCHEMES:
        raise AppmodeError(f"unknown URL scheme {scheme + '://'!r} in {url!r}: {URL_HELP}")
    if scheme in NETWORK_SCHEMES:
        _check_address(url, scheme)
    if scheme == "sim":
        from appmode.ports.sim import parse_sim_url

        try:
            return Target(url, scheme, sim=parse_sim_url(url))
        except SerialException as exc:
            raise AppmodeError(str(exc)) from None
    return Target(url, scheme)


def as_target(url: Target | str) -> Target:
    return url if isinstance(url, Target) else parse_target(url)


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
    from urllib.parse import parse_qs

    for name, values in parse_qs(query, keep_blank_values=True).items():
        if name != "baud":
            raise AppmodeError(f"unknown option {name!r} in {url!r}: only ?baud=N is known")
        if not params.whole(values[-1]):
            raise AppmodeError(f"bad baud rate {values[-1]!r} in {url!r}: use e.g. ?baud=9600")
        baud = int(values[-1].strip())
    return path, baud
