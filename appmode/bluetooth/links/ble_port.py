"""`ble://`: a BLE "transparent UART" module (HM-10, HC-08, JDY-08/10, BT05, CC41, or a
Nordic UART Service) as a pyserial port, on bleak.

Notifications become the byte stream `read` returns, in order. `write` queues; a writer
sends the queue in writes of at most the connection's MTU − 3 bytes (20 unless the link
negotiated more), without response where the characteristic allows, and never faster
than the module's UART forwards them at 9600 bps: the module holds what the radio brings
faster in a buffer of a few hundred bytes at most, and what comes when it is full is
lost (bluetooth.module models it). A lost connection makes the next `read` or `write`
raise SerialException, as an unplugged adapter does, so a host's link reconnects.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from serial import SerialBase, SerialException, SerialTimeoutException

from appmode.bluetooth.availability import NO_BLEAK, explain
from appmode.bluetooth.inbox import Inbox
from appmode.bluetooth.loop import LoopThread
from appmode.bluetooth.module import PAYLOAD
from appmode.bluetooth.uuids import UART_SERVICES, UartService, uart_service
from appmode.line.pacing import Ahead
from appmode.ports.radio import BLE_USAGE, BleTarget
from appmode.ports.urls import port_target

if TYPE_CHECKING:
    from bleak import BleakClient
    from bleak.backends.characteristic import BleakGATTCharacteristic
    from bleak.backends.device import BLEDevice
    from bleak.backends.scanner import AdvertisementData

SCAN = 6.0
"""Seconds to look for the module before saying it is not nearby."""
NAME_WINDOW = 1.5
"""Seconds to go on listening once a module of the asked name is heard: a second module
of that name (two cars of one kit) makes the name ambiguous."""
CONNECT = 10.0
WRITE_BUFFER = 4096
"""Bytes `write` may queue ahead of the radio; past them it waits (its write_timeout)."""
AHEAD = PAYLOAD
"""Bytes the writer lets the module's buffer hold beyond what its UART has sent."""
CLOSE = 3.0
LINGER = 0.05
"""Seconds between the last write and hanging up: a few connection events, so that
what the radio holds (a session's stop) is sent before the link ends."""
BAUD = 9600


class BleSerial(SerialBase):  # type: ignore[misc]  # pyserial has no types
    """A BLE UART module, opened by `ble://` URL."""

    on_notified: Callable[[int], None] | None = None
    """Called (on the port's loop) with the size of each notification as it comes, before
    `read` can return it: a hook for timing the radio's part of a round trip."""

    def open(self) -> None:
        if self._port is None:
            raise SerialException("port must be configured before use")
        target = port_target(self).radio
        if not isinstance(target, BleTarget):
            raise SerialException(f"expected {BLE_USAGE}, not {self.portstr!r}")
        try:
            import bleak  # noqa: F401
        except ImportError:
            raise SerialException(NO_BLEAK) from None
        logging.getLogger("bleak.backends.bluezdbus.version").setLevel(logging.ERROR)
        self._target = target
        self._ready = threading.Condition()
        self._received = Inbox(self._ready)
        self._lost: str | None = None
        self._queued = 0
        self._runner = LoopThread(f"ble {target.shown}")
        self._queue: asyncio.Queue[bytes] | None = None
        self._client: BleakClient | None = None
        try:
            self._runner.run(self._connect(target), SCAN + CONNECT + 2)
        except TimeoutError:
            self._runner.close()
            raise SerialException(
                f"{target.shown} did not answer within {SCAN + CONNECT:g} s: switch the "
                "car on and bring it in range"
            ) from None
        except Exception as exc:
            self._runner.close()
            raise SerialException(explain(exc) or str(exc)) from None
        self.is_open = True

    async def _connect(self, target: BleTarget) -> None:
        from bleak import BleakClient, BleakScanner

        if target.address is not None:
            device = await BleakScanner.find_device_by_address(target.address, timeout=SCAN)
        else:
            assert target.name is not None
            device = await _named(target.name)
        if device is None:
            raise SerialException(
                f"no BLE device {target.shown} nearby (looked for {SCAN:g} s): switch the "
                "car on, bring it in range, or see what is near with appmode scan"
            )
        client = BleakClient(device, disconnected_callback=self._disconnected)
        await client.connect(timeout=CONNECT)
        try:
            service = UartService("named", *target.service) if target.service else _uart(client)
            write = client.services.get_characteristic(service.write)
            notify = client.services.get_characteristic(service.notify)
            if write is None or notify is None:
                raise SerialException(f"{target.shown} has no {service.name} characteristics")
            await client.start_notify(notify, self._notified)
        except BaseException:
            await client.disconnect()
            raise
        self._client = client
        self._queue = asyncio.Queue()
        self._writer = asyncio.ensure_future(self._write_loop(client, write))

    def _notified(self, _: Any, data: bytearray) -> None:
        if self.on_notified is not None:
            self.on_notified(len(data))
        self._received.add(data)

    def _disconnected(self, _: Any) -> None:
        with self._ready:
            self._lost = f"the Bluetooth connection to {self._target.shown} was lost"
            self._ready.notify_all()

    async def _write_loop(self, client: BleakClient, write: BleakGATTCharacteristic) -> None:
        assert self._queue is not None
        size = max(PAYLOAD, write.max_write_without_response_size)
        response = "write-without-response" not in write.properties
        ahead = Ahead(BAUD, AHEAD)
        while True:
            data = await self._queue.get()
            for start in range(0, len(data), size):
                chunk = data[start : start + size]
                wait = ahead.delay(time.monotonic())
                if wait:
                    await asyncio.sleep(wait)
                try:
                    await client.write_gatt_char(write, chunk, response=response)
                except Exception as exc:  # the link is gone: said once
                    self._disconnected(exc)
                    return
                ahead.wrote(len(chunk), time.monotonic())
                with self._ready:
                    self._queued -= len(chunk)
                    self._ready.notify_all()

    # ------------------------------------------------------------ pyserial

    def _reconfigure_port(self) -> None:
        """A radio link has no line settings to change."""

    def _check(self) -> None:
        if not self.is_open:
            raise SerialException("the port is not open")
        if self._lost is not None:
            raise SerialException(self._lost)

    @property
    def in_waiting(self) -> int:
        self._check()
        return len(self._received)

    def read(self, size: int = 1) -> bytes:
        return self._received.read(size, self._timeout, self._check)

    def write(self, data: bytes) -> int:
        self._check()
        data = bytes(data)
        if not data:
            return 0
        deadline = None if self._write_timeout is None else time.monotonic() + self._write_timeout
        with self._ready:
            while self._queued + len(data) > WRITE_BUFFER and self._queued:
                self._check()
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    raise SerialTimeoutException("write timeout")
                self._ready.wait(left)
            self._queued += len(data)
        queue = self._queue
        assert queue is not None
        self._runner.loop.call_soon_threadsafe(queue.put_nowait, data)
        return len(data)

    def flush(self) -> None:
        """Wait until what was written has gone to the module (the link lost: at once)."""
        with self._ready:
            while self._queued and self._lost is None:
                self._ready.wait(0.1)

    def reset_input_buffer(self) -> None:
        self._received.clear()

    def close(self) -> None:
        """What was written goes first (a session's stop is its last write), then the
        connection ends."""
        if not self.is_open:
            return
        self.is_open = False
        deadline = time.monotonic() + CLOSE + self._queued / (BAUD / 10)
        with self._ready:
            while self._queued and self._lost is None and time.monotonic() < deadline:
                self._ready.wait(0.05)
        if self._lost is None:
            time.sleep(LINGER)
        client = self._client
        if client is not None:
            with contextlib.suppress(Exception):  # gone already: nothing to end
                self._runner.run(client.disconnect(), CLOSE)
        self._runner.close()


def _uart(client: BleakClient) -> UartService:
    service = uart_service([s.uuid for s in client.services])
    if service is None:
        found = ", ".join(s.uuid for s in client.services) or "none"
        known = ", ".join(s.name for s in UART_SERVICES)
        raise SerialException(
            f"{client.address} offers no UART service appmode knows ({known}); name it "
            f"with ?service=…&write=…&notify=… (its services: {found})"
        )
    return service


async def _named(name: str) -> BLEDevice | None:
    """The one module heard advertising `name`, None if none is heard within SCAN;
    SerialException naming their addresses when more than one is."""
    from bleak import BleakScanner

    found: dict[str, BLEDevice] = {}
    heard = asyncio.Event()

    def advertised(device: BLEDevice, adv: AdvertisementData) -> None:
        if (adv.local_name or device.name) == name:
            found[device.address] = device
            heard.set()

    async with BleakScanner(detection_callback=advertised):
        try:
            await asyncio.wait_for(heard.wait(), SCAN)
        except asyncio.TimeoutError:
            return None
        await asyncio.sleep(NAME_WINDOW)
    if len(found) > 1:
        addresses = sorted(found)
        raise SerialException(
            f"{len(found)} BLE devices nearby are called {name!r} ({', '.join(addresses)}): "
            f"choose one by its address, such as ble://{addresses[0]}"
        )
    return next(iter(found.values()))
