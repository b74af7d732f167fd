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

from dbus_fast import DBusError, Message, MessageType, Variant
from dbus_fast.aio import MessageBus
from dbus_fast.annotations import DBusStr
from dbus_fast.service import ServiceInterface, dbus_method

from appmode.bluetooth.gatt import Cccd, GattService, UartCharacteristic
from appmode.bluetooth.loop import chunks
from appmode.bluetooth.module import CONNECTION_INTERVAL, ModuleModel, next_event
from appmode.bluetooth.signatures import Nothing
from appmode.bluetooth.standin.devices import ADAPTER, Adapter, Device
from appmode.bluetooth.standin.peers import Peers
from appmode.bluetooth.standin.spp_links import new_connection
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


class Control(ServiceInterface):
    """What a test asks of the stand-in that no radio API has: drop the connections now
    (the car out of range, switched off), and how many bytes the module lost."""

    def __init__(self, standin: StandIn) -> None:
        super().__init__("org.appmode.StandIn1")
        self._standin = standin

    @dbus_method()
    def Drop(self) -> Nothing:
        self._standin.drop("dropped by request")

    @dbus_method()
    def Nearby(self, name: DBusStr) -> Nothing:
        """Another BLE module nearby, advertising `name` ("": the car's module's name, a
        second HC-08), at an address of its own; it takes no connection."""
        self._standin.nearby(name or BLE_NAME)


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
        self.others: list[Device] = []
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
        self._profiles: list[tuple[str, str, str, str]] = []  # (sender, path, uuid, role)
        self.peers = Peers(self, log, lambda: self.adapter.discovering)
        self._discoverers: set[str] = set()
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
        bus.add_message_handler(self._peer_message)
        bus.export(ADAPTER, self.adapter)
        self.peers.start(bus)
        bus.export(self.spp.path, self.spp)  # paired: BlueZ knows it from the start
        bus.export(CONTROL, Control(self))
        reply = await bus.request_name("org.bluez")
        if reply.value != 1:  # PRIMARY_OWNER
            raise OSError(f"org.bluez is already served on {self._address}")
        self._board.setblocking(False)
        self._spawn(self._from_board())
        self._spawn(self._events())

    async def run(self, stop: asyncio.Event, ready: Callable[[], None]) -> None:
        """Serve until `stop` is set; `ready` is called once the API is on the bus."""
        await self.start()
        ready()
        try:
            await stop.wait()
        finally:
            self.drop("the stand-in stops")
            self.peers.close()
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
        started = on and not self.adapter.discovering
        self.adapter.set_discovering(on)
        if on and not self._found and self._bus is not None:
            self._found = True
            self._bus.export(self.ble.path, self.ble)
        if started:
            self.peers.discovered()
            self._spawn(self._advertise())

    async def _advertise(self) -> None:
        while self.adapter.discovering:
            for device in [self.ble, *self.others, *self.peers.heard()]:
                device.advertise(-58 + random.randint(-4, 4))
            await asyncio.sleep(ADVERTISING)

    def nearby(self, name: str) -> None:
        """Another module advertising `name` (its UART service too), at its own address."""
        address = f"02:CA:40:00:01:{len(self.others):02X}"
        device = Device(self, address, name, list(self.ble.uuids), le=True)
        self.others.append(device)
        if self._bus is not None:
            self._bus.export(device.path, device)

    # ------------------------------------------------------------ connections

    async def connect(self, device: Device, uuid: str | None) -> None:
        if device in self.others:
            raise DBusError(FAILED, f"{device.label} is not the car's module")
        peer = self.peers.owner(device)
        if peer is not None and device.le:
            self.peers.connect_ble(peer, device)
            return
        if peer is not None:
            await self.peers.connect_spp(peer, device, self._client_profile(device, uuid or SPP))
            return
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
        if self._spp_link is not None:
            raise DBusError("org.bluez.Error.AlreadyConnected", "Already Connected")
        assert self._bus is not None
        mine = await new_connection(self._bus, self._client_profile(device, uuid), device.path)
        self._spp_link = mine
        device.set_state(True)
        self._log(f"spp: {device.label} connected")
        self._spp_reader = asyncio.ensure_future(self._from_spp(mine, device))

    def _client_profile(self, device: Device, uuid: str) -> tuple[str, str]:
        """The profile registered last to connect to `uuid` as a client: BlueZ hands it
        the connection."""
        if uuid != SPP:
            raise DBusError("org.bluez.Error.NotAvailable", f"{device.label} offers only SPP")
        for sender, path, registered, role in reversed(self._profiles):
            if registered == SPP and role != "server":
                return sender, path
        raise DBusError(
            "org.bluez.Error.NotAvailable",
            "no application registered the Serial Port profile (ProfileManager1)",
        )

    def disconnect(self, device: Device) -> None:
        peer = self.peers.owner(device)
        if peer is not None:
            if device.le:
                self.peers.disconnect_ble(peer, device)
            else:
                self.peers.spp_links.disconnect(device)
            return
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
        """Every link ends at once, as when the car goes out of range."""
        peers = [d for p in self.peers.all() for d in (p.ble, p.spp) if d is not None]
        for device in (self.ble, self.spp, *peers):
            if device.connected:
                self._log(f"{why}: {device.label}")
            self.disconnect(device)

    def _profile_manager(self, message: Message) -> Message | None:
        """org.bluez.ProfileManager1, answered here: it needs the caller's bus name."""
        if message.interface != "org.bluez.ProfileManager1" or message.path != "/org/bluez":
            return None
        sender = str(message.sender)
        if message.member == "RegisterProfile" and message.signature == "osa{sv}":
            path, uuid, options = message.body
            role = str(options.get("Role", Variant("s", "")).value)
            self._profiles.append((sender, path, uuid.lower(), role))
            if role == "server" and uuid.lower() == SPP:
                self.peers.profile(sender, path, options, added=True)
            return Message.new_method_return(message)
        if message.member == "UnregisterProfile" and message.signature == "o":
            path = message.body[0]
            self._profiles = [p for p in self._profiles if (p[0], p[1]) != (sender, path)]
            self.peers.profile(sender, path, {}, added=False)
            return Message.new_method_return(message)
        return Message.new_error(message, "org.bluez.Error.InvalidArguments", "bad call")

    def _peer_message(self, message: Message) -> bool:
        """What the server side takes: GattManager1's and LEAdvertisingManager1's calls,
        an application's notifications, a registered client leaving the bus."""
        if message.message_type == MessageType.METHOD_CALL:
            return self._discovery(message) or self.peers.handle(message)
        if message.message_type == MessageType.SIGNAL:
            self._session_ends(message)
            return self.peers.notified(message) or self.peers.gone(message)
        return False

    def _discovery(self, message: Message) -> bool:
        """Adapter1.StartDiscovery and StopDiscovery: as BlueZ, one discovery session per
        client, and the adapter discovers while any is open (one client stopping does
        not stop another's)."""
        if message.path != ADAPTER or message.interface != "org.bluez.Adapter1":
            return False
        if message.member not in ("StartDiscovery", "StopDiscovery") or self._bus is None:
            return False
        sender = str(message.sender)
        if message.member == "StartDiscovery":
            if sender not in self._discoverers:
                self._discoverers.add(sender)
                self.peers.spawn(self.peers.watch_name(sender))
        elif sender in self._discoverers:
            self._discoverers.discard(sender)
        else:
            self._bus.send(Message.new_error(message, FAILED, "No discovery started"))
            return True
        self.discover(bool(self._discoverers))
        self._bus.send(Message.new_method_return(message))
        return True

    def _session_ends(self, message: Message) -> None:
        """A client that left the bus leaves its discovery session."""
        if message.member == "NameOwnerChanged" and message.signature == "sss":
            name, _, new = message.body
            if not new and name in self._discoverers:
                self._discoverers.discard(name)
                self.discover(bool(self._discoverers))

    # ------------------------------------------------------------ bytes

    def _from_central(self, data: bytes, device: str) -> None:
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

    async def _from_board(self) -> None:
        async for data in chunks(self._board):
            if self.ble.connected and self.characteristic.notifying:
                self.module.from_uart(data)
            if self._spp_link is not None:
                with contextlib.suppress(OSError):  # a host that reads nothing: dropped
                    self._spp_link.send(data)

    async def _from_spp(self, link: socket.socket, device: Device) -> None:
        spp = ModuleModel()
        async for data in chunks(link):
            self._to_board(spp.from_radio(data, time.monotonic()))
        if self._spp_link is link:
            self.disconnect(device)
