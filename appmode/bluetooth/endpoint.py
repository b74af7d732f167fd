"""`appmode board --bluetooth`: the board's APP port served through the BlueZ stand-in on
a private bus, as an endpoint of the board server (ports.endpoints). The stand-in runs
in a thread of its own with its own event loop; the two meet at a socket pair."""

from __future__ import annotations

import asyncio
import selectors
import socket
import threading

from appmode.bluetooth.bus import PrivateBus
from appmode.bluetooth.standin import BLE_ADDRESS, BLE_NAME, SPP_ADDRESS, StandIn
from appmode.errors import AppmodeError
from appmode.ports.endpoints import Log, Overrun

START = 10.0
"""Seconds the stand-in may take to be on its bus."""


class BluetoothEndpoint:
    """The simulated car's module on a private bus: `bus` is the address to put in
    DBUS_SYSTEM_BUS_ADDRESS, `url` the `ble://` URL that reaches it."""

    def __init__(self, sel: selectors.BaseSelector, log: Log, baud: int | None = None) -> None:
        self.baud = baud
        self._sel = sel
        self._private = PrivateBus()
        self.bus = self._private.address
        self.url = f"ble://{BLE_ADDRESS}"
        self.details: tuple[str, ...] = (
            f"bus: {self.bus}",
            f"ble: {BLE_ADDRESS} {BLE_NAME}",
            f"spp: {SPP_ADDRESS}",
        )
        self._mine, theirs = socket.socketpair()
        self._mine.setblocking(False)
        self._out = Overrun(log, "the stand-in")
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Event | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self.standin = StandIn(self.bus, theirs, log)
        self._thread = threading.Thread(target=self._run, name="bluez-standin", daemon=True)
        self._thread.start()
        if not self._ready.wait(START) or self._error is not None:
            why = self._error or f"not ready within {START:g} s"
            self.close()
            raise AppmodeError(f"the BlueZ stand-in did not start: {why}")
        sel.register(self._mine, selectors.EVENT_READ, self)

    def _run(self) -> None:
        asyncio.run(self._main())

    async def _main(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        try:
            await self.standin.run(self._stop, self._ready.set)
        except Exception as exc:
            self._error = exc
            self._ready.set()

    def pause(self, paused: bool) -> None:
        if paused:
            self._sel.unregister(self._mine)
        else:
            self._sel.register(self._mine, selectors.EVENT_READ, self)

    def read(self, size: int, ready: object) -> bytes:
        try:
            return self._mine.recv(size)
        except (BlockingIOError, InterruptedError):
            return b""

    def write(self, data: bytes) -> None:
        self._out.write(data, self._mine.send)

    def close(self) -> None:
        loop, stop = self._loop, self._stop
        if loop is not None and stop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(stop.set)
        self._thread.join(5)
        self._mine.close()
        self._private.close()
