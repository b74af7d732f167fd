"""Over `ble://` through the BlueZ stand-in, beside a pty:

- `{Q:P}` → C: a board that answers at once behind the stand-in (a process of its own,
  as bluetoothd is), timed at each step. The modelled radio holds a write until the next
  connection event and a notification until the one after the answer; the platform
  (bleak, D-Bus, the stand-in in bluetoothd's place) carries both; appmode's own share
  is the ble:// port's: from `write` to bleak's write, and from bleak's notification to
  `read`. Target: p99 < 2 ms. Beside it, the same `{Q:P}` → C over a pty to a served
  board, beyond its next telemetry slot.
- sustained writes: 1920 bytes (2 s at 9600 bps) written at once reach the module no
  faster than its UART forwards them (960 bytes/s), and no slower than 95 % of that.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import random
import selectors
import statistics
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from multiprocessing.connection import Connection
from typing import Any

import serial

import appmode  # noqa: F401 - registers ble://
from appmode.bluetooth.links.ble_port import AHEAD
from appmode.bluetooth.module import CONNECTION_INTERVAL, PAYLOAD, UART_BYTES_PER_S
from appmode.bluetooth.standin.endpoint import BluetoothEndpoint
from appmode.testing.process import board_process
from bench import link_roundtrip
from bench.common import Row, percentile

ANSWER = b"{C500:10000:20:0:10:10:10:0:0}$"
SENT = 1920


@contextmanager
def ble_board() -> Iterator[str]:
    """`appmode board --bluetooth --no-pace`; yields its ble:// URL, with this process's
    DBUS_SYSTEM_BUS_ADDRESS set to its bus meanwhile."""
    with board_process("--quiet", "--bluetooth", "--no-pace") as served:
        before = os.environ.get("DBUS_SYSTEM_BUS_ADDRESS")
        os.environ["DBUS_SYSTEM_BUS_ADDRESS"] = served.details["bus"]
        try:
            yield served.url
        finally:
            if before is None:
                del os.environ["DBUS_SYSTEM_BUS_ADDRESS"]
            else:
                os.environ["DBUS_SYSTEM_BUS_ADDRESS"] = before


def send_rate(url: str) -> float:
    """Bytes per second a burst of SENT bytes goes out at, until the port has sent all:
    the last AHEAD bytes, and the write under way, are in the module's buffer then, not
    yet out of its UART."""
    port = serial.serial_for_url(url, timeout=0.1)
    started_at = time.monotonic()
    port.write(b"J" * SENT)
    port.flush()
    took = time.monotonic() - started_at
    port.close()
    return (SENT - AHEAD - PAYLOAD) / took


def echo_board(bus: Connection, trials: int) -> None:
    """In a process of its own, as bluetoothd is: the stand-in with a board that answers
    at once; sends its bus, then for each trial when the write reached the stand-in, the
    board, and when the answer was notified (time.monotonic: one clock for the machine)."""
    sel = selectors.DefaultSelector()
    endpoint = BluetoothEndpoint(sel, lambda _: None)
    standin = endpoint.standin
    marks: dict[str, float] = {}

    def timed(name: str, call: Callable[..., None]) -> Callable[..., None]:
        def wrapper(*args: object) -> None:
            marks[name] = time.monotonic()
            call(*args)

        return wrapper

    standin.characteristic.notify = timed(  # type: ignore[method-assign]
        "notified", standin.characteristic.notify
    )
    standin.characteristic._received = timed("written", standin.characteristic._received)
    bus.send(endpoint.bus)
    for _ in range(trials):
        while not sel.select(1):
            pass
        board_got = time.monotonic()
        endpoint.read(64, None)
        endpoint.write(ANSWER)
        bus.recv()  # the host has the answer: the marks are set
        bus.send((marks["written"], board_got, marks["notified"]))
    endpoint.close()


def own_latency(trials: int) -> tuple[list[float], list[float], list[float]]:
    """Round trips of `{Q:P}` → C through the stand-in to a board that answers at once
    (ms), and two shares of each: the platform's (bleak, D-Bus, and the stand-in in
    bluetoothd's place) and appmode's own (from `write` to bleak's write, and from
    bleak's last notification to `read` returning). The rest is the modelled radio."""
    from bleak import BleakClient

    host: dict[str, float] = {}
    write_gatt_char = BleakClient.write_gatt_char

    async def timed_write(self: BleakClient, *args: Any, **kwargs: Any) -> None:
        host["gatt"] = time.monotonic()
        await write_gatt_char(self, *args, **kwargs)

    def timed_notified(size: int) -> None:
        host["callback"] = time.monotonic()

    mine, theirs = multiprocessing.Pipe()
    child = multiprocessing.Process(target=echo_board, args=(theirs, trials), daemon=True)
    child.start()
    before = os.environ.get("DBUS_SYSTEM_BUS_ADDRESS")
    os.environ["DBUS_SYSTEM_BUS_ADDRESS"] = mine.recv()
    BleakClient.write_gatt_char = timed_write  # type: ignore[method-assign]
    port = serial.serial_for_url("ble://HC-08", timeout=1)
    port.on_notified = timed_notified
    trips, platform, own = [], [], []
    rng = random.Random(1)
    try:
        for _ in range(trials):
            time.sleep(rng.uniform(0, 2 * CONNECTION_INTERVAL))
            sent = time.monotonic()
            port.write(b"{Q:P}")
            got = b""
            while not got.endswith(b"$"):
                got += port.read(64)
            done = time.monotonic()
            mine.send(None)
            written, _, answered = mine.recv()
            trips.append((done - sent) * 1000)
            platform.append((written - host["gatt"] + host["callback"] - answered) * 1000)
            own.append((host["gatt"] - sent + done - host["callback"]) * 1000)
    finally:
        port.close()
        BleakClient.write_gatt_char = write_gatt_char  # type: ignore[method-assign]
        child.join(10)
        if before is None:
            del os.environ["DBUS_SYSTEM_BUS_ADDRESS"]
        else:
            os.environ["DBUS_SYSTEM_BUS_ADDRESS"] = before
    return trips, platform, own


def rows(quick: bool) -> list[Row]:
    trials = 50 if quick else 200
    with board_process("--quiet", "--pty", "--no-pace") as served:
        pty = served.url
        on_pty = [x * 1000 for x in link_roundtrip.measure(pty, trials)]
    trips, platform, own = own_latency(trials)
    with ble_board() as url:
        rate = send_rate(url)
    p99 = percentile(own, 99)
    return [
        Row(
            "{Q:P} -> C over a pty, beyond the next slot",
            f"median {statistics.median(on_pty):.2f} ms, p99 {percentile(on_pty, 99):.2f} ms",
            "",
            None,
        ),
        Row(
            "{Q:P} -> C over ble:// (stand-in, board answering at once): round trip",
            f"median {statistics.median(trips):.2f} ms, p99 {percentile(trips, 99):.2f} ms "
            f"(connection events every {CONNECTION_INTERVAL * 1000:.0f} ms)",
            "",
            None,
        ),
        Row(
            "{Q:P} -> C over ble://: the platform's share (bleak, D-Bus, the stand-in)",
            f"median {statistics.median(platform):.2f} ms, p99 {percentile(platform, 99):.2f} ms",
            "",
            None,
        ),
        Row(
            "{Q:P} -> C over ble://: appmode's own share (the ble:// port)",
            f"median {statistics.median(own):.2f} ms, p99 {p99:.2f} ms",
            "p99 < 2 ms",
            p99 < 2,
        ),
        Row(
            f"ble:// sustained write of {SENT} bytes",
            f"{rate:.0f} bytes/s = {rate / UART_BYTES_PER_S * 100:.1f} % of 960",
            ">= 95 %, <= 100.5 % of 960",
            0.95 * UART_BYTES_PER_S <= rate <= 1.005 * UART_BYTES_PER_S,
        ),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    for row in rows(args.quick):
        print(f"{row.benchmark}: {row.result} (target {row.target or '-'})")


if __name__ == "__main__":
    main()
