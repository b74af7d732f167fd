"""A driver's heartbeats over UDP, beside Zenoh's: over a link that loses packets, TCP
holds every later heartbeat back until a lost one is sent again (0.4–0.9 s at 5 % loss,
past the lease's 0.3 s), while a datagram lost is only that one. The car's host listens
on the port number its share listens on; a driver sends each heartbeat — `NAME CLIENT
COUNT MAC`, proven as on Zenoh (`proof`; bare until its lease's secret has come) — to the
addresses its URL connects to. Nothing else travels this way, and a datagram renews
only what the same heartbeat on Zenoh would (`lease.Lease.beat`).

Through a router the driver's datagrams reach the router: it relays each to the car's
host that greeted it last for the car's name (`+hello NAME COUNT MAC`, every second,
from a socket connected to the router, under the room's host key, each count higher
than the last: a stranger can neither greet for a car nor replay a greeting)."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any

from appmode.net.proof import Proof, mac

DATAGRAM = 512
"""Bytes of a heartbeat at most (a car's name, a client's, a count and an HMAC)."""
PER_SECOND = 200
"""Datagrams read a second at most (a driver sends 20): a flood waits in the kernel's
buffer, which drops what overflows, and takes no more of the share's time than this."""
RELAYED = 2000
"""Datagrams a router relays a second at most (a room's drivers send 20 each)."""
HELLO = "+hello"
"""A car's host's greeting to a router (no car's name begins with `+`)."""
GREET_EVERY = 1.0
"""Seconds between a car's host's greetings to each router it connects to."""


def address_of(endpoint: str) -> tuple[str, int] | None:
    """The host and port of a `tcp/` or `tls/` endpoint; None for another."""
    scheme, _, rest = endpoint.partition("/")
    host, _, port = rest.rpartition(":")
    if scheme not in ("tcp", "tls") or not host or not port.isdigit():
        return None
    return host.strip("[]"), int(port)


class _Datagrams(ABC):
    """A UDP socket read in a thread of its own, at most `per_second` datagrams a
    second, each `heard` as its words, its bytes and where it came from."""

    def __init__(self, sock: socket.socket, per_second: int) -> None:
        self._socket = sock
        self._per_second = per_second
        self._ended = threading.Event()
        self._thread = threading.Thread(target=self._listen, name="udp beats", daemon=True)
        self._thread.start()

    @abstractmethod
    def heard(self, words: list[str], data: bytes, sender: Any) -> None:
        """A datagram read: its words, its bytes, where it came from."""

    def _listen(self) -> None:
        second, read = time.monotonic(), 0
        while True:
            read += 1
            if read > self._per_second:
                time.sleep(max(0.0, second + 1 - time.monotonic()))
                second, read = time.monotonic(), 1
            try:
                data, sender = self._socket.recvfrom(DATAGRAM)
            except OSError:  # closed (or, connected, the router's port refused a greeting)
                if self._ended.is_set():
                    return
                continue
            with contextlib.suppress(UnicodeDecodeError):
                words = data.decode().split(" ")
                if all(map(str.isprintable, words)):
                    self.heard(words, data, sender)

    def close(self) -> None:
        self._ended.set()
        with contextlib.suppress(OSError):
            self._socket.shutdown(socket.SHUT_RDWR)
        self._socket.close()
        self._thread.join(1.0)


def _bound(host: str, port: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.bind((host, port))
    except OSError:
        sock.close()
        raise
    return sock


class BeatListener(_Datagrams):
    """The car's host's side: datagrams on `sock`, each for the car `name` `heard` as
    its words after the name."""

    def __init__(self, sock: socket.socket, name: str, heard: Callable[[list[str]], None]) -> None:
        self._name = name
        self._on_beat = heard
        super().__init__(sock, PER_SECOND)

    @classmethod
    def on(
        cls, host: str, port: int, name: str, heard: Callable[[list[str]], None]
    ) -> BeatListener:
        """Listening on (`host`, `port`), where drivers send their heartbeats."""
        return cls(_bound(host, port), name, heard)

    def heard(self, words: list[str], data: bytes, sender: Any) -> None:
        if words[0] == self._name:
            self._on_beat(words[1:])


class RelayedBeats(BeatListener):
    """The car's host's side through a router (its address): a socket of its own,
    connected to the router's port (it hears the router alone), greeting it every
    GREET_EVERY s under `host_key` so that it relays the car's heartbeats here."""

    def __init__(
        self, router: tuple[str, int], name: str, heard: Callable[[list[str]], None], host_key: str
    ) -> None:
        host, port = router
        family, _, _, _, where = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)[0]
        sock = socket.socket(family, socket.SOCK_DGRAM)
        sock.connect(where)
        super().__init__(sock, name, heard)
        greet = threading.Thread(target=self._greet, args=(host_key,), name="udp hello")
        greet.daemon = True
        greet.start()

    def _greet(self, host_key: str) -> None:
        while True:
            count = time.time_ns() // 1000  # higher at each greeting, across restarts
            hello = f"{HELLO} {self._name} {count} {mac(host_key, count, HELLO, self._name)}"
            with contextlib.suppress(OSError):  # unreachable: its heartbeats go on Zenoh
                self._socket.send(hello.encode())
            if self._ended.wait(GREET_EVERY):
                return


class BeatRelay(_Datagrams):
    """A router's side: datagrams on (`host`, `port`), each relayed to the car's host
    that greeted it last, under `host_key`, for the car its first word names."""

    def __init__(self, host: str, port: int, host_key: str) -> None:
        self._host_key = host_key
        self._hosts: dict[str, tuple[Any, int]] = {}
        """Each car's host, by the car's name: where it greeted from, its last count."""
        super().__init__(_bound(host, port), RELAYED)

    def heard(self, words: list[str], data: bytes, sender: Any) -> None:
        if words[0] != HELLO:
            where = self._hosts.get(words[0])
            if where is not None:
                with contextlib.suppress(OSError):
                    self._socket.sendto(data, where[0])
            return
        proof = Proof.parse(words) if len(words) == 4 else None
        if proof is None or not proof.holds(self._host_key, HELLO, words[1]):
            return
        last = self._hosts.get(words[1])
        if last is None or proof.count > last[1]:
            self._hosts[words[1]] = (sender, proof.count)


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
