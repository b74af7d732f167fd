"""Two machines joined by a poor link, for the network's tests: the car's host and a
laptop in network namespaces, each with a TUN device, and a thread here carrying every
IP packet from one to the other after `delay` seconds, dropping `loss` of them at random
(each way). The kernel's TCP in each namespace sees real loss and delay, as on a WAN
(the machine has no netem). `cut()` drops everything: a link really lost."""

from __future__ import annotations

import contextlib
import fcntl
import heapq
import os
import random
import select
import struct
import subprocess
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

from tests.support.netns import Machine

TUNSETIFF = 0x400454CA
IFF_TUN, IFF_NO_PI = 0x0001, 0x1000
ADDRESSES = {"car": "10.78.0.1", "laptop": "10.78.0.2"}


class Link:
    """The link's state: its delay and loss, and the packets it carried and dropped."""

    def __init__(self, delay: float, loss: float, seed: int) -> None:
        self.delay, self.loss = delay, loss
        self.carried = self.dropped = 0
        self._random = random.Random(seed)
        self._lock = threading.Lock()

    def cut(self) -> None:
        """The link lost: nothing more gets across, what is in flight included."""
        with self._lock:
            self.loss = 1.0

    def is_cut(self) -> bool:
        with self._lock:
            return self.loss >= 1.0

    def drops(self) -> bool:
        with self._lock:
            dropped = self._random.random() < self.loss
        if dropped:
            self.dropped += 1
        else:
            self.carried += 1
        return dropped


def _tun(name: str) -> int:
    fd = os.open("/dev/net/tun", os.O_RDWR)
    fcntl.ioctl(fd, TUNSETIFF, struct.pack("16sH", name.encode(), IFF_TUN | IFF_NO_PI))
    os.set_blocking(fd, False)
    return fd


def _carry(fds: dict[int, int], link: Link, done: threading.Event) -> None:
    """Each packet read from one TUN device written to the other `link.delay` later."""
    due: list[tuple[float, int, int, bytes]] = []
    count = 0
    while not done.is_set():
        wait = max(0.0, min(0.05, due[0][0] - time.monotonic())) if due else 0.05
        ready, _, _ = select.select(list(fds), [], [], wait)
        for fd in ready:
            while True:
                try:
                    packet = os.read(fd, 65536)
                except BlockingIOError:
                    break
                if not link.drops():
                    count += 1
                    heapq.heappush(due, (time.monotonic() + link.delay, count, fds[fd], packet))
        now = time.monotonic()
        while due and due[0][0] <= now:
            _, _, to, packet = heapq.heappop(due)
            if link.is_cut():
                continue  # in flight when the link was lost: lost with it
            with contextlib.suppress(OSError):  # a device going down: the packet is lost
                os.write(to, packet)


@contextmanager
def wan(delay: float, loss: float, seed: int = 7) -> Iterator[tuple[dict[str, Machine], Link]]:
    """The car's host and a laptop (10.78.0.1 and .2) over a link of `delay` s and `loss`
    each way; torn down after."""
    tag = f"aw{os.getpid() % 100000}"
    link = Link(delay, loss, seed)
    made: list[str] = []
    fds: list[int] = []
    done = threading.Event()
    carrier = None

    def ip(*args: str) -> None:
        subprocess.run(["ip", *args], check=True, capture_output=True)

    try:
        machines: dict[str, Machine] = {}
        for name, address in ADDRESSES.items():
            netns, device = f"{tag}-{name}", f"{tag}{name[0]}"
            ip("netns", "add", netns)
            made.append(netns)
            fds.append(_tun(device))
            ip("link", "set", device, "netns", netns)
            peer = next(a for n, a in ADDRESSES.items() if n != name)
            ip("-n", netns, "addr", "add", address, "peer", peer, "dev", device)
            ip("-n", netns, "link", "set", device, "up")
            ip("-n", netns, "link", "set", "lo", "up")
            machines[name] = Machine(netns, address, device)
        carrier = threading.Thread(
            target=_carry, args=({fds[0]: fds[1], fds[1]: fds[0]}, link, done), daemon=True
        )
        carrier.start()
        yield machines, link
    finally:
        done.set()
        if carrier is not None:
            carrier.join(2)
        for fd in fds:
            os.close(fd)
        for netns in made:
            subprocess.run(["ip", "netns", "del", netns], capture_output=True)
