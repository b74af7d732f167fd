"""A Zenoh session as appmode opens one: its mode, where it listens and connects, its
key (Zenoh's user-password authentication: a session without the right key is refused
at the transport, before any key expression is seen), TLS, and whether it scouts the
LAN by multicast. Also what a failure to open says, in a line."""

from __future__ import annotations

import contextlib
import json
import os
import re
import socket
import tempfile
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Literal

from appmode.errors import AppmodeError, install_line
from appmode.net.names import HOST_USER, USER
from appmode.net.roles import access_control

if TYPE_CHECKING:
    import zenoh

Mode = Literal["peer", "client", "router"]
NO_ZENOH = (
    f"the network needs eclipse-zenoh and cryptography: {install_line('net')}; both have "
    "wheels for Linux, macOS and Windows on x86-64 and ARM, a Raspberry Pi too"
)
CLOSING = 1.0
"""Seconds a session is given to close: Zenoh waits up to ten for a peer whose network
is gone to hear it, and nothing of the car's safety waits on that (its stop is sent
before)."""
SOURCE = re.compile(r"\s+at \S+\.rs:\d+\.?")
"""Where in Zenoh's Rust sources an error was raised: no help to a user."""


@dataclass(frozen=True, slots=True)
class Tls:
    """TLS for `tls/` endpoints: a listener's certificate and key, a client's CA."""

    certificate: str | None = None
    private_key: str | None = None
    root_ca: str | None = None


def zenoh_module() -> object:
    """The zenoh package; AppmodeError with what to install when it is not there."""
    try:
        import cryptography  # noqa: F401  # what a car's host says is signed (`signature`)
        import zenoh
    except ImportError:
        raise AppmodeError(NO_ZENOH) from None
    return zenoh


ACCEPT_TIMEOUT_MS = 2000
"""How long a listening session waits for a new connection's handshake (Zenoh's default:
10 s): a connection that says nothing, a stranger's, is dropped after it."""
ACCEPT_PENDING = 2000
"""Connections in their handshake at once at most (Zenoh's default: 100, which ~300
idle connections of a stranger without the key filled, keeping `fleet stop` out)."""


def open_session(
    mode: Mode,
    key: str | None,
    listen: tuple[str, ...] = (),
    connect: tuple[str, ...] = (),
    scout: bool = False,
    tls: Tls | None = None,
    config_file: str | None = None,
    host_key: str | None = None,
) -> zenoh.Session:
    """A Zenoh session (`key` None: no authentication, as ROS's own sessions; a
    `config_file` is Zenoh's own configuration, used as it is); with `host_key`, a car's
    host's or a router's: it connects as a host, admits the key's holders and the room's
    hosts, and holds its key holders to their role (`roles`). AppmodeError (one line, no
    source paths) when it cannot open: nothing listens where it connects, or the key was
    refused."""
    import zenoh

    if config_file is not None:
        try:
            return zenoh.open(zenoh.Config.from_file(config_file))
        except zenoh.ZError as exc:
            raise AppmodeError(
                f"the Zenoh configuration {config_file}: {trimmed(str(exc))}"
            ) from None
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("listen/endpoints", json.dumps(list(listen)))
    config.insert_json5("connect/endpoints", json.dumps(list(connect)))
    config.insert_json5("scouting/multicast/enabled", json.dumps(scout))
    if listen:  # strangers' idle connections may not keep a key holder out
        config.insert_json5("transport/unicast/accept_timeout", json.dumps(ACCEPT_TIMEOUT_MS))
        config.insert_json5("transport/unicast/accept_pending", json.dumps(ACCEPT_PENDING))
    if tls is not None:
        if tls.root_ca is not None and not Path(tls.root_ca).is_file():
            raise AppmodeError(
                f"ca={tls.root_ca}: no such file: give the certificate appmode share --tls "
                "named, copied to this machine"
            )
        _tls(config, tls)
    with tempfile.TemporaryDirectory(prefix="appmode-zenoh-") as folder:
        if key is not None:  # None: as ROS's sessions, anyone who reaches it
            admits = bool(listen) or mode == "router"
            auth = _auth(key, host_key, Path(folder), admits)
            config.insert_json5("transport/auth/usrpwd", json.dumps(auth))
            if host_key is not None and admits:
                config.insert_json5("access_control", json.dumps(access_control()))
        try:
            return zenoh.open(config)
        except zenoh.ZError as exc:
            bare = any(e.startswith("tls/") for e in connect) and (tls is None or not tls.root_ca)
            ca = None if tls is None else tls.root_ca
            stale = None if ca is None else certificate_refused(connect, ca)
            raise AppmodeError(stale or opening_failed(str(exc), listen, connect, bare)) from None


def certificate_refused(connect: tuple[str, ...], ca: str) -> str | None:
    """Why a `tls/` endpoint was not reached, when it is its certificate: a TLS handshake
    of our own against each, trusting `ca` alone (Zenoh's own error does not say)."""
    import socket
    import ssl

    for endpoint in (e for e in connect if e.startswith("tls/")):
        host, _, port = endpoint.removeprefix("tls/").rpartition(":")
        context = ssl.create_default_context(cafile=ca)
        context.check_hostname = False  # the share's certificate names its machine
        try:
            with (
                socket.create_connection((host.strip("[]"), int(port)), timeout=2) as raw,
                context.wrap_socket(raw),
            ):
                pass
        except ssl.SSLCertVerificationError:
            return (
                f"cannot reach {endpoint}: its certificate is not the one in ca={ca} (the "
                "share's certificate changed, or the file is another's): copy share-cert.pem "
                "from the car's host again, and check its fingerprint"
            )
        except (OSError, ValueError):
            continue  # nothing listens, or another failure: Zenoh's error says it
    return None


def _auth(key: str, host_key: str | None, folder: Path, admits: bool) -> dict[str, str]:
    """User-password authentication with `key` (as a host with `host_key`); a session
    that `admits` others (it listens, or routes) takes only the key's holders and, for a
    host, the room's hosts (a file in `folder`, yours alone)."""
    auth = {"user": USER, "password": key}
    if host_key is not None:
        auth = {"user": HOST_USER, "password": host_key}
    if admits:
        users = folder / "users"
        fd = os.open(users, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w", encoding="utf-8") as file:
            file.write(f"{USER}:{key}\n")
            if host_key is not None:
                file.write(f"{HOST_USER}:{host_key}\n")
        auth["dictionary_file"] = str(users)
    return auth


def free_port(listen: str) -> str:
    """`listen` with a free port in place of port 0 (Zenoh does not say which it took)."""
    prefix, _, port = listen.rpartition(":")
    if port != "0":
        return listen
    host = prefix.split("/", 1)[1].strip("[]")
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as probe:
        probe.bind((host, 0))
        return f"{prefix}:{probe.getsockname()[1]}"


def close_session(session: zenoh.Session, within: float = CLOSING) -> None:
    """Close `session`, waiting at most `within` seconds (the rest happens in the
    background, or not at all when the process ends first)."""

    def close() -> None:
        with contextlib.suppress(Exception):  # a peer that did not hear the close
            session.close()  # type: ignore[no-untyped-call]

    closing = threading.Thread(target=close, name="zenoh close", daemon=True)
    closing.start()
    closing.join(within)


def _tls(config: zenoh.Config, tls: Tls) -> None:
    parts = {
        "listen_certificate": tls.certificate,
        "listen_private_key": tls.private_key,
        "root_ca_certificate": tls.root_ca,
    }
    for name, value in parts.items():
        if value is not None:
            config.insert_json5(f"transport/link/tls/{name}", json.dumps(value))
    if tls.certificate is not None:  # a TLS listener joins no peer it hears of: nothing
        # plain reaches it through another share of its key, nor it through a plain one
        none = json.dumps({"router": [], "peer": [], "client": ["router", "peer"]})
        config.insert_json5("scouting/multicast/autoconnect", none)
        config.insert_json5("scouting/gossip/enabled", "false")


def trimmed(text: str) -> str:
    """Zenoh's message without where in its sources it was raised."""
    return SOURCE.sub("", text).strip().rstrip(".!")


def opening_failed(
    text: str, listen: tuple[str, ...], connect: tuple[str, ...], tls_without_ca: bool = False
) -> str:
    """What a Zenoh session that did not open means, and what to do."""
    why = trimmed(text)
    if tls_without_ca:
        return (
            f"cannot reach {', '.join(connect)}: a tls/ endpoint needs the share's "
            "certificate: add &ca=FILE to the URL (the file appmode share --tls named)"
        )
    if connect and "connect" in why.lower():
        return (
            f"cannot reach {', '.join(connect)}: nothing listens there, or it refused this "
            "key (use the URL appmode share printed, key included)"
        )
    if not connect and not listen and "timeout" in why.lower():  # a client that scouts
        return (
            "found no car's host on this network with this key: no share runs, the key "
            "is not its own (give --key: the key= part of the URL appmode share printed), "
            "or multicast is blocked here (give --connect tcp/HOST:7447)"
        )
    if listen and ("bind" in why.lower() or "in use" in why.lower()):
        return f"cannot listen on {', '.join(listen)} ({why}): pick another with --listen"
    return f"cannot open the Zenoh session: {why}"
