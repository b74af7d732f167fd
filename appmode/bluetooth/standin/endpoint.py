"""The board's APP port served over Bluetooth, as endpoints of the board server
(ports.endpoints): `BluetoothEndpoint` (`appmode board --bluetooth`) serves the BlueZ
stand-in on a private bus with the car as its nearby module; `AdvertisedEndpoint`
(`appmode board --advertise`) registers the car as a module with the BlueZ of the
system bus, for a phone to connect to. Each runs its event loop in a thread of its own;
the loop and the server meet at a socket pair."""

from __future__ import annotations

import asyncio
import contextlib
import selectors
import socket
import sys
import threading
from collections.abc import Callable, Coroutine

from appmode.bluetooth.advertise.admission import ANY_PHONE, Admission
from appmode.bluetooth.advertise.application import AdvertisedModule
from appmode.bluetooth.loop import chunks
from appmode.bluetooth.standin.bluez import BLE_ADDRESS, BLE_NAME, SPP_ADDRESS, StandIn
from appmode.bluetooth.standin.bus import PrivateBus
from appmode.bluetooth.uuids import UartService
from appmode.errors import AppmodeError
from appmode.ports.endpoints import Log, Overrun

START = 10.0
"""Seconds the loop's service may take to be on its bus."""
Serve = Callable[[asyncio.Event, Callable[[], None]], Coroutine[object, object, None]]
"""Serves until the event is set; calls the function once it is ready."""


class LoopEndpoint:
    """An endpoint whose client side is served by `serve` on an event loop in a thread;
    `board` is the loop's end of the socket pair (what it writes reaches the board)."""

    details: tuple[str, ...] = ()

    def __init__(self, sel: selectors.BaseSelector, log: Log, name: str) -> None:
        self._sel = sel
        self._mine, self.board = socket.socketpair()
        self._mine.setblocking(False)
        self._out = Overrun(log, name)
        self._name = name
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Event | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._thread: threading.Thread | None = None

    def _start(self, serve: Serve) -> None:
        """Run `serve` in the loop's thread; AppmodeError if it fails to start."""
        self._thread = threading.Thread(target=asyncio.run, args=(self._main(serve),), daemon=True)
        self._thread.start()
        if not self._ready.wait(START) or self._error is not None:
            error = self._error
            self.close()
            if isinstance(error, AppmodeError):
                raise error
            why = error or f"not ready within {START:g} s"
            raise AppmodeError(f"{self._name} did not start: {why}")
        self._sel.register(self._mine, selectors.EVENT_READ, self)

    async def _main(self, serve: Serve) -> None:
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        try:
            await serve(self._stop, self._ready.set)
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
            with contextlib.suppress(RuntimeError):  # the loop ended meanwhile
                loop.call_soon_threadsafe(stop.set)
        if self._thread is not None:
            self._thread.join(5)
        self._mine.close()
        self.board.close()


class BluetoothEndpoint(LoopEndpoint):
    """The simulated car's module on a private bus: `bus` is the address to put in
    DBUS_SYSTEM_BUS_ADDRESS, `url` the `ble://` URL that reaches it."""

    def __init__(self, sel: selectors.BaseSelector, log: Log, baud: int | None = None) -> None:
        self._private = PrivateBus()
        super().__init__(sel, log, "the BlueZ stand-in")
        self.baud = baud
        self.bus = self._private.address
        self.url = f"ble://{BLE_ADDRESS}"
        self.details = (
            f"bus: {self.bus}",
            f"ble: {BLE_ADDRESS} {BLE_NAME}",
            f"spp: {SPP_ADDRESS}",
        )
        self.standin = StandIn(self.bus, self.board, log)
        self._start(self.standin.run)

    def close(self) -> None:
        super().close()
        self._private.close()


class AdvertisedEndpoint(LoopEndpoint):
    """The simulated car as a module registered with the system bus's BlueZ (a real
    adapter, or a stand-in's bus named by DBUS_SYSTEM_BUS_ADDRESS): advertised on BLE as
    `name` with `service`, and offered as an SPP server."""

    def __init__(
        self,
        sel: selectors.BaseSelector,
        log: Log,
        name: str,
        service: UartService,
        baud: int | None = None,
        admission: Admission = ANY_PHONE,
    ) -> None:
        super().__init__(sel, log, f"the advertised module {name}")
        self.baud = baud
        self.url = f"ble://{name}"
        self.module = AdvertisedModule(name, service, log, self._to_board, admission=admission)
        self._start(self._serve)
        if (warning := admission.warning(name)) is not None:  # said once it is on the air
            print(f"board: {warning}", file=sys.stderr, flush=True)
        self.details = (
            f"ble: advertised as {name} ({service.name}) on {self.module.adapter}",
            f"spp: {name} (server)",
        )

    def _to_board(self, data: bytes) -> None:
        with contextlib.suppress(BlockingIOError):  # the board reads all it is sent
            self.board.send(data)

    async def _serve(self, stop: asyncio.Event, ready: Callable[[], None]) -> None:
        self.board.setblocking(False)
        try:
            await self.module.start()
        except BaseException:
            await self.module.stop()
            raise
        ready()
        pump = asyncio.ensure_future(self._from_board())
        try:
            await stop.wait()
        finally:
            pump.cancel()
            await self.module.stop()

    async def _from_board(self) -> None:
        async for data in chunks(self.board):
            self.module.send(data)
