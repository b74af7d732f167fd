"""The driver's heartbeats as datagrams (`net.beats`): heard for the car named, nothing
else; a flood read at a bounded rate, the rest left to the kernel to drop; through a
router, relayed to the car's host that greeted it under the room's host key alone."""

from __future__ import annotations

import socket
import threading
import time

from appmode.net.beats import (
    HELLO,
    PER_SECOND,
    BeatListener,
    BeatRelay,
    BeatSender,
    RelayedBeats,
    address_of,
)
from appmode.net.proof import mac


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def test_a_driver_s_datagrams_are_heard_for_its_car_only_and_a_flood_is_bounded() -> None:
    port = free_udp_port()
    heard: list[list[str]] = []
    lock = threading.Lock()

    def on_heard(words: list[str]) -> None:
        with lock:
            heard.append(words)

    listener = BeatListener.on("127.0.0.1", port, "car-1", on_heard)
    sender = BeatSender((f"tcp/127.0.0.1:{port}", "udp/127.0.0.1:9", "tcp/nowhere"))
    try:
        sender.send("car-1 laptop-1-abc 7 " + "0" * 32)
        sender.send("car-2 laptop-1-abc 8 " + "0" * 32)  # another car's
        sender.send("car-1 \x1b[2J 9 x")  # not printable
        time.sleep(0.3)
        assert heard == [["laptop-1-abc", "7", "0" * 32]]
        start = time.monotonic()
        for n in range(5 * PER_SECOND):
            sender.send(f"car-1 flood-{n} 1 x")
        time.sleep(0.5)
        with lock:
            read = len(heard) - 1
        assert read <= PER_SECOND + 1 or time.monotonic() - start > 1.0, read
    finally:
        sender.close()
        listener.close()
    assert address_of("tls/[::1]:7450") == ("::1", 7450) and address_of("udp/h:1") is None


def test_a_router_relays_a_car_s_heartbeats_to_the_host_that_greeted_it_alone() -> None:
    port = free_udp_port()
    relay = BeatRelay("127.0.0.1", port, "room host key")
    heard: list[list[str]] = []
    host = RelayedBeats(("127.0.0.1", port), "car-1", heard.append, "room host key")
    stranger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    stranger.bind(("127.0.0.1", 0))
    stranger.settimeout(0.2)
    sender = BeatSender((f"tcp/127.0.0.1:{port}",))
    try:
        time.sleep(0.3)  # the host's first greeting
        sender.send("car-1 laptop-1-abc 7 " + "0" * 32)
        sender.send("car-2 laptop-1-abc 8 " + "0" * 32)  # no host greeted for car-2
        count = time.time_ns() // 1000
        for hello in (
            f"{HELLO} car-1 {count + 10**9} {mac('a guess', count + 10**9, HELLO, 'car-1')}",
            f"{HELLO} car-1 1 {mac('room host key', 1, HELLO, 'car-1')}",  # replayed: older
        ):
            stranger.sendto(hello.encode(), ("127.0.0.1", port))
        time.sleep(0.1)
        sender.send("car-1 laptop-1-abc 9 " + "1" * 32)
        time.sleep(0.3)
        assert heard == [["laptop-1-abc", "7", "0" * 32], ["laptop-1-abc", "9", "1" * 32]]
        try:
            taken = stranger.recv(512)
        except TimeoutError:
            taken = b""
        assert taken == b"", "a stranger's greeting takes no car's heartbeats"
    finally:
        for each in (sender, host, relay, stranger):
            each.close()
