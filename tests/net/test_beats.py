"""The driver's heartbeats as datagrams (`net.beats`): heard for the car named, nothing
else; a flood read at a bounded rate, the rest left to the kernel to drop."""

from __future__ import annotations

import socket
import threading
import time

from appmode.net.beats import PER_SECOND, BeatListener, BeatSender, address_of


def test_a_driver_s_datagrams_are_heard_for_its_car_only_and_a_flood_is_bounded() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    heard: list[list[str]] = []
    lock = threading.Lock()

    def on_heard(words: list[str]) -> None:
        with lock:
            heard.append(words)

    listener = BeatListener("127.0.0.1", port, "car-1", on_heard)
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
