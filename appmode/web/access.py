"""Who may use the web page, with no I/O: the owner's token, the Host header (no DNS
rebinding) and the websocket's Origin (no cross-site page drives the car)."""

from __future__ import annotations

import ipaddress
import secrets
from urllib.parse import urlsplit

COOKIE = "appmode_token"
TOKEN_BYTES = 24
"""192 bits of randomness in each token."""


def new_token() -> str:
    return secrets.token_urlsafe(TOKEN_BYTES)


def token_matches(token: str, given: str | None) -> bool:
    """Whether `given` is the token, compared in constant time."""
    return given is not None and secrets.compare_digest(token.encode(), given.encode())


def is_loopback(host: str) -> bool:
    """Whether a listening address is this machine alone."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def allowed_hosts(host: str, port: int) -> frozenset[str]:
    """The Host headers a request to this server may carry: the address it listens on,
    and the loopback names when that is loopback — never a name some DNS could point at
    it (a rebinding page would carry its own)."""
    names = {host}
    if is_loopback(host):
        names |= {"127.0.0.1", "localhost", "[::1]"}
    if ":" in host and not host.startswith("["):
        names.add(f"[{host}]")
    return frozenset(f"{name}:{port}" for name in names)


def origin_matches(origin: str | None, host: str, scheme: str) -> bool:
    """Whether a websocket's Origin is this page itself (same scheme, host and port)."""
    if origin is None:
        return False
    parts = urlsplit(origin)
    return parts.scheme == scheme and parts.netloc == host and not parts.path.strip("/")
