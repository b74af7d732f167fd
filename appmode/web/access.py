"""Who may use the web page, with no I/O: the owner's token, the Host header (no DNS
rebinding) and the websocket's Origin (no cross-site page drives the car)."""

from __future__ import annotations

import ipaddress
import secrets
import socket
from urllib.parse import urlsplit

COOKIE = "appmode_token"
TOKEN_BYTES = 24
"""192 bits of randomness in each token."""


def new_token() -> str:
    return secrets.token_urlsafe(TOKEN_BYTES)


def token_matches(token: str, given: str | None) -> bool:
    """Whether `given` is the token, compared in constant time (a header's bytes that are
    no UTF-8 are simply not the token)."""
    if given is None:
        return False
    return secrets.compare_digest(token.encode(), given.encode("utf-8", "surrogatepass"))


def is_loopback(host: str) -> bool:
    """Whether a listening address is this machine alone."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


WILDCARDS = ("0.0.0.0", "::", "")
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "::1")


def _is_address(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def host_allowed(header: str | None, listen: str, port: int) -> bool:
    """Whether a request's Host header names this server (so a page on another name
    that DNS points here — a rebinding attack — is refused): the address it listens on
    with its port; on loopback the loopback names; on a wildcard address any address
    literal, or this machine's own name."""
    if header is None:
        return False
    host, colon, given = header.rpartition(":")
    if not colon or given != str(port):
        return False
    name, listen = host.strip("[]").lower(), listen.strip("[]").lower()
    if name == listen:
        return True
    if is_loopback(listen):
        return name in LOOPBACK_NAMES
    if listen in WILDCARDS:
        own = socket.gethostname().lower()
        return _is_address(name) or name in ("localhost", own, f"{own}.local")
    return False


def origin_matches(origin: str | None, host: str, scheme: str) -> bool:
    """Whether a websocket's Origin is this page itself (same scheme, host and port)."""
    if origin is None:
        return False
    parts = urlsplit(origin)
    return parts.scheme == scheme and parts.netloc == host and not parts.path.strip("/")
