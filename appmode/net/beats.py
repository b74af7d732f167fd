"""A driver's heartbeats over UDP, beside Zenoh's: over a link that loses packets, TCP
holds every later heartbeat back until a lost one is sent again (0.4–0.9 s at 5 % loss,
past the lease's 0.3 s), while a datagram lost is only that one. The car's host listens
on the port number its share listens on; a driver sends each heartbeat — `NAME CLIENT
COUNT MAC`, proven as on Zenoh (`proof`; bare until its lease's secret has come) — to the
addresses its URL connects to. Nothing else travels this way, and a datagram renews
only what the same heartbeat on Zenoh would (`lease.Lease.beat`)."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

DATAGRAM = 512
"""Bytes of a heartbeat at most (a car's name, a client's, a count and an HMAC)."""
PER_SECOND = 200
"""Datagrams read a second at most (a driver sends 20): a flood waits in the kernel's
buffer, which drops what overflows, and takes no more of the share's time than this."""


def address_of(endpoint: str) -> tuple[str, int] | None:
    """The host and port of a `tcp/` or `tls/` endpoint; None for another."""
    scheme, _, rest = endpoint.partition("/")
    host, _, port = rest.rpartition(":")
    if scheme not in ("tcp", "tls") or not host or not port.isdigit():
        return None
    return host.strip("[]"), int(port)


class BeatListener:
    """The car's host's side: datagrams on (`host`, `port`), each for the car `name`
    `heard` as its words after the name."""

    def __init__(self, host: str, port: int, name: str, heard: Callable[[list[str]], None]) -> None:
        self._name = name
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        self._socket = socket.socket(family, socket.SOCK_DGRAM)
        self._socket.bind((host, port))
        self._heard = heard
        self._thread = threading.Thread(target=self._listen, name="udp beats", daemon=True)
        self._thread.start()

    def _listen(self) -> None:
        second, read = time.monotonic(), 0
        while True:
            read += 1
            if read > PER_SECOND:
                time.sleep(max(0.0, second + 1 - time.monotonic()))
                second, read = time.monotonic(), 1
            try:
                data = self._socket.recv(DATAGRAM)
            except OSError:  # closed
                return
            with contextlib.suppress(UnicodeDecodeError):
                words = data.decode().split(" ")
                if words[0] == self._name and all(map(str.isprintable, words)):
                    self._heard(words[1:])

    def close(self) -> None:
        with contextlib.suppress(OSError):
            self._socket.shutdown(socket.SHUT_RDWR)
        self._socket.close()
        self._thread.join(1.0)


class BeatSender:
    """A driver's side: each heartbeat to every address it was given (none: it sends
    nothing, and its heartbeats go on Zenoh alone)."""

    def __init__(self, endpoints: tuple[str, ...]) -> None:
        self._sockets: list[tuple[socket.socket, tuple[Any, ...]]] = []
        for address in filter(None, map(address_of, endpoints)):
            with contextlib.suppress(OSError):  # a name that does not resolve: Zenoh's alone
                family, _, _, _, where = socket.getaddrinfo(*address, type=socket.SOCK_DGRAM)[0]
                self._sockets.append((socket.socket(family, socket.SOCK_DGRAM), where))

    def send(self, text: str) -> None:
        data = text.encode()
        for sock, where in self._sockets:
            with contextlib.suppress(OSError):  # unreachable, or nothing listens: Zenoh's
                sock.sendto(data, where)

    def close(self) -> None:
        for sock, _ in self._sockets:
            sock.close()
