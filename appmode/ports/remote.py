"""What a `zenoh://` URL names, with no I/O: a car shared with `appmode share` — its
name, where to reach it (Zenoh endpoints; none: found by scouting on the LAN), the key
that admits a client, the id of the host that signs for the car, whether to take the
driving over, a CA certificate for `tls/` endpoints. `target.parse_target` reads it
once; `net/` opens it."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

from serial import SerialException

NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}")
"""A car's name: a Zenoh key's chunk, no wildcards or separators."""
ENDPOINT = re.compile(r"(tcp|tls)/(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.-]+):([0-9]{1,5})")
"""A Zenoh endpoint appmode reaches a share or a router at."""
USAGE = "zenoh://NAME?connect=tcp/HOST:PORT&key=KEY (as appmode share printed it)"
OPTIONS = ("connect", "key", "id", "port", "take", "ca")
HOST_ID = re.compile(r"[A-Za-z0-9_-]{43}")
"""A car's host's id: the public half of the room's signing key, base64url
(`net.signature`)."""


class BadRemote(ValueError):
    """What is wrong with the URL, and how to write it."""


class WriteRefused(SerialException):  # type: ignore[misc]  # pyserial has no types
    """The car's host refused the bytes (another client drives): the link is up, nothing
    was sent."""


@dataclass(frozen=True, slots=True)
class RemoteTarget:
    """A shared car: its name, the endpoints to connect to, the key, `take` (drive it
    though another client does), a CA certificate file for `tls/` endpoints, the id of
    the host that signs for it (None: the first met, then kept)."""

    name: str
    connect: tuple[str, ...]
    key: str
    take: bool = False
    ca: str | None = None
    host_id: str | None = None


def check_endpoint(text: str, listening: bool = False) -> str:
    """`text` if it is a `tcp/HOST:PORT` or `tls/HOST:PORT` endpoint (port 0, a free one,
    where `listening`); BadRemote if not."""
    found = ENDPOINT.fullmatch(text)
    if found is None or not (0 if listening else 1) <= int(found.group(3)) < 65536:
        raise BadRemote(f"{text!r} is not an endpoint: use tcp/HOST:PORT (or tls/HOST:PORT)")
    return text


def parse_remote(name: str, options: Mapping[str, str], url: str) -> RemoteTarget:
    """A `zenoh://` URL's name and options (`url` is what messages quote, its key hidden)."""
    if not NAME.fullmatch(name):
        raise BadRemote(f"{name!r} in {url!r} is not a car's name: letters, digits, - and _")
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise BadRemote(f"unknown option {unknown[0]!r} in {url!r}: use {', '.join(OPTIONS)}")
    key = options.get("key", "")
    if not key:
        raise BadRemote(f"{url!r} has no key: {USAGE}")
    connect = tuple(check_endpoint(e) for e in options.get("connect", "").split(",") if e)
    if options.get("take", "0") not in ("0", "1"):
        raise BadRemote(f"take={options['take']!r} in {url!r}: take=1 takes the driving over")
    host_id = options.get("id")
    if host_id is not None and not HOST_ID.fullmatch(host_id):
        raise BadRemote(
            f"id={host_id!r} in {url!r} is no host id: copy the URL appmode share printed"
        )
    take = options.get("take") == "1"
    return RemoteTarget(name, connect, key, take, options.get("ca"), host_id)
