"""The BlueZ stand-in: BlueZ's D-Bus API (org.bluez on a private bus), whose adapter's
nearby devices are one simulated car's module — as a BLE UART module (HC-08: service
FFE0, characteristic FFE1) and as a paired classic SPP module (HC-05) — bridged to the
board's APP port through a socket. It emulates the API, not a radio: bleak and any
program written for BlueZ run against it unmodified.

The module between radio and board is `module.ModuleModel`: connection events, 20-byte
notifications, a 9600-bps UART behind a small input buffer.
"""

from __future__ import annotations

import asyncio
import contextlib
import random
import socket
import time
from collections.abc import Callable, Coroutine

from dbus_fast import DBusError, Message, MessageType
from dbus_fast.aio import MessageBus
from dbus_fast.service import ServiceInterface, dbus_method

from appmode.bluetooth.devices import ADAPTER, Adapter, Device
from appmode.bluetooth.gatt import Cccd, GattService, UartCharacteristic
from appmode.bluetooth.module import CONNECTION_INTERVAL, ModuleModel, next_event
from appmode.bluetooth.signatures import Nothing
from appmode.bluetooth.uuids import SPP, UART_SERVICES

Log = Callable[[str], None]
BLE_ADDRESS = "02:CA:40:00:00:08"
SPP_ADDRESS = "02:CA:40:00:00:05"
BLE_NAME, SPP_NAME = "HC-08", "HC-05"
"""Locally administered addresses (no vendor's) and the names these modules ship with."""
ADVERTISING = 0.1
"""Seconds between two advertisements heard while discovering."""
CONTROL = "/org/appmode/standin"
FAILED = "org.bluez.Error.Failed"
READ = 4096


class Control(ServiceInterface):
    """What a test asks of the stand-in that no radio API has: drop the connections now
    (the car out of range, switched off), and how many bytes the module lost."""

    def __init__(self, standin: StandIn) -> None:
        super().__init__("org.appmode.StandIn1")
        self._standin = standin

    @dbus_method()
    def Drop(self) -> Nothing:
        self._standin.drop("dropped by request")


class StandIn:
    """Serves BlueZ's API on `bus_address` for the board behind `board` (a connected
    socket: what is written to it reaches the board's APP port, what the board sends is
    read from it)."""

    def __init__(self, bus_address: str, board: socket.socket, log: Log) -> None:
        self._address = bus_address
        self._board = board
        self._log = log
        self._bus: MessageBus | None = None
        self.adapter = Adapter(self, "02:CA:40:00:00:01")
        service = UART_SERVICES[0]
        self.ble = Device(self, BLE_ADDRESS, BLE_NAME, [service.service], le=True)
        self.spp = Device(self, SPP_ADDRESS, SPP_NAME, [SPP], le=False)
        base = f"{self.ble.path}/service0010"
        self._gatt: list[tuple[str, ServiceInterface]] = [
            (base, GattService(service.service, self.ble.path, 0x10)),
        ]
        self.characteristic = UartCharacteristic(service.write, base, 0x11, self._from_central)
        self._gatt += [
            (f"{base}/char0011", self.characteristic),
            (f"{base}/char0011/desc0013", Cccd(f"{base}/char0011", 0x13)),
        ]
        self.module = ModuleModel()
        self._writes: list[bytes] = []
        self._profiles: list[tuple[str, str, str]] = []  # (sender, path, uuid)
        self._spp_link: socket.socket | None = None
        self._spp_reader: asyncio.Task[None] | None = None
        self._tasks: set[asyncio.Task[None]] = set()
        self._found = False
        self._linked = asyncio.Event()
        self._origin = time.monotonic()

    async def start(self) -> None:
        bus = await MessageBus(bus_address=self._address, negotiate_unix_fd=True).connect()
        self._bus = bus
        bus.add_message_handler(self._profile_manager)
        bus.export(ADAPTER, self.adapter)
        bus.export(self.spp.path, self.spp)  # paired: BlueZ knows it from the start
        bus.export(CONTROL, Control(self))
        reply = await bus.request_name("org.bluez")
        if reply.value != 1:  # PRIMARY_OWNER
            raise OSError(f"org.bluez is already served on {self._address}")
        loop = asyncio.get_running_loop()
        self._board.setblocking(False)
        self._spawn(self._from_board(loop))
        self._spawn(self._events())

    async def run(self, stop: asyncio.Event, ready: Callable[[], None]) -> None:
        """Serve until `stop` is set; `ready` is called once the API is on the bus."""
        await self.start()
        ready()
        try:
            await stop.wait()
        finally:
            self.drop("the stand-in stops")
            for task in self._tasks:
                task.cancel()
            if self._bus is not None:
                self._bus.disconnect()

    def _spawn(self, work: Coroutine[object, object, None]) -> None:
        task = asyncio.ensure_future(work)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    # ------------------------------------------------------------ discovery

    def discover(self, on: bool) -> None:
        self.adapter.set_discovering(on)
        if on and not self._found and self._bus is not None:
            self._found = True
            self._bus.export(self.ble.path, self.ble)
        if on:
            self._spawn(self._advertise())

    async def _advertise(self) -> None:
        while self.adapter.discovering:
            self.ble.advertise(-58 + random.randint(-4, 4))
            await asyncio.sleep(ADVERTISING)

    # ------------------------------------------------------------ connections

    async def connect(self, device: Device, uuid: str | None) -> None:
        if device.le:
            if uuid is not None and uuid not in device.uuids:
                raise DBusError(FAILED, f"{device.label} has no profile {uuid}")
            if not device.connected and self._bus is not None:
                self.module = ModuleModel()
                self._origin = time.monotonic()
                while self._gatt:  # resolved once: BlueZ keeps a device's services
                    self._bus.export(*self._gatt.pop(0))
                await asyncio.sleep(CONNECTION_INTERVAL)
                device.set_state(True)
                self._linked.set()
                self._log(f"ble: {device.label} connected")
            return
        await self._connect_spp(device, uuid or SPP)

    async def _connect_spp(self, device: Device, uuid: str) -> None:
        if uuid != SPP:
            raise DBusError("org.bluez.Error.NotAvailable", f"{device.label} offers only SPP")
        if self._spp_link is not None:
            raise DBusError("org.bluez.Error.AlreadyConnected", "Already Connected")
        registered = [p for p in reversed(self._profiles) if p[2] == SPP]
        if not registered or self._bus is None:
            raise DBusError(
                "org.bluez.Error.NotAvailable",
                "no application registered the Serial Port profile (ProfileManager1)",
            )
        sender, path, _ = registered[0]
        mine, theirs = socket.socketpair()
        reply = await self._bus.call(
            Message(
                destination=sender,
                path=path,
                interface="org.bluez.Profile1",
                member="NewConnection",
                signature="oha{sv}",
                body=[device.path, 0, {}],
                unix_fds=[theirs.fileno()],
            )
        )
        theirs.close()
        if reply is None or reply.message_type == MessageType.ERROR:
            mine.close()
            why = reply.body[0] if reply is not None and reply.body else "no answer"
            raise DBusError(FAILED, f"the profile refused the connection: {why}")
        mine.setblocking(False)
        self._spp_link = mine
        device.set_state(True)
        self._log(f"spp: {device.label} connected")
        self._spp_reader = asyncio.ensure_future(self._from_spp(mine, device))

    def disconnect(self, device: Device) -> None:
        if not device.le and self._spp_link is not None:
            reader = self._spp_reader
            if reader is not None and reader is not asyncio.current_task():
                reader.cancel()  # before the close: a socket closed under a read is a
                # descriptor the loop still watches, and the next link may get its number
            self._spp_reader = None
            self._spp_link.close()
            self._spp_link = None
        if device.le:
            self._deliver()  # what a central wrote goes before the link ends
        if device.le:
            self._linked.clear()
        if device.connected:
            device.set_state(False)
            self._log(f"{'ble' if device.le else 'spp'}: {device.label} disconnected")
        if device.le:
            self.characteristic.notifying = False

    def drop(self, why: str) -> None:
        """Both links end at once, as when the car goes out of range."""
        for device in (self.ble, self.spp):
            if device.connected:
                self._log(f"{why}: {device.label}")
            self.disconnect(device)

    def _profile_manager(self, message: Message) -> Message | None:
        """org.bluez.ProfileManager1, answered here: it needs the caller's bus name."""
        if message.interface != "org.bluez.ProfileManager1" or message.path != "/org/bluez":
            return None
        if message.member == "RegisterProfile" and message.signature == "osa{sv}":
            path, uuid, _ = message.body
            self._profiles.append((str(message.sender), path, uuid.lower()))
            return Message.new_method_return(message)
        if message.member == "UnregisterProfile" and message.signature == "o":
            self._profiles = [
                p for p in self._profiles if (p[0], p[1]) != (message.sender, message.body[0])
            ]
            return Message.new_method_return(message)
        return Message.new_error(message, "org.bluez.Error.InvalidArguments", "bad call")

    # ------------------------------------------------------------ bytes

    def _from_central(self, data: bytes) -> None:
        """A central's write: it reaches the module at the next connection event."""
        if self.ble.connected:
            self._writes.append(data)

    async def _events(self) -> None:
        """The BLE connection's events: writes in, notifications out (none while no
        central is connected: the stand-in sleeps)."""
        while True:
            if not self.ble.connected:
                await self._linked.wait()
            now = time.monotonic()
            await asyncio.sleep(next_event(now, self._origin) - now)
            self._deliver()
            for chunk in self.module.notifications():
                self.characteristic.notify(chunk)

    def _deliver(self) -> None:
        """The writes made since the last connection event reach the module."""
        for data in self._writes:
            self._to_board(self.module.from_radio(data, time.monotonic()))
        self._writes.clear()

    def _to_board(self, data: bytes) -> None:
        """Bytes out of the module's UART (the board's end reads all it is sent)."""
        with contextlib.suppress(BlockingIOError):
            self._board.send(data)

    async def _from_board(self, loop: asyncio.AbstractEventLoop) -> None:
        while True:
            data = await loop.sock_recv(self._board, READ)
            if not data:
                return
            if self.ble.connected and self.characteristic.notifying:
                self.module.from_uart(data)
            if self._spp_link is not None:
                with contextlib.suppress(OSError):  # a host that reads nothing: dropped
                    self._spp_link.send(data)

    async def _from_spp(self, link: socket.socket, device: Device) -> None:
        loop = asyncio.get_running_loop()
        spp = ModuleModel()
        while True:
            try:
                data = await loop.sock_recv(link, READ)
            except OSError:
                data = b""
            if not data:
                break
            self._to_board(spp.from_radio(data, time.monotonic()))
        if self._spp_link is link:
            self.disconnect(device)
