"""The module's side of the radio: appmode as a Bluetooth UART module (an HC-08 or HM-10
on BLE, an HC-05 on classic SPP) that a phone connects to, through BlueZ's D-Bus API
(org.bluez.GattManager1, LEAdvertisingManager1, ProfileManager1 in BlueZ's doc/).

A GATT application (service FFE0 with characteristic FFE1, or the Nordic UART service)
registered with `GattManager1.RegisterApplication`, advertised under a name with
`LEAdvertisingManager1.RegisterAdvertisement`, and an SPP server registered with
`ProfileManager1.RegisterProfile`. What the phone writes reaches `received` through the
module's input buffer (`module.ModuleModel`); what `send` is given goes out as
notifications of at most 20 bytes, a few per connection event, and to an SPP link.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import socket
import time
from collections.abc import Callable
from typing import Any

from dbus_fast import BusType, DBusError, Message, MessageType, Variant
from dbus_fast.aio import MessageBus
from dbus_fast.annotations import DBusDict, DBusObjectPath, DBusStr, DBusUnixFd
from dbus_fast.constants import PropertyAccess
from dbus_fast.service import ServiceInterface, dbus_method, dbus_property

from appmode.bluetooth.advertise.admission import ANY_PHONE, SECURE_FLAGS, Admission
from appmode.bluetooth.availability import explain
from appmode.bluetooth.calls import BLUEZ, add_match, call
from appmode.bluetooth.gatt import Characteristic, Service
from appmode.bluetooth.loop import chunks
from appmode.bluetooth.module import CONNECTION_INTERVAL, ModuleModel
from appmode.bluetooth.signatures import DBusStrings, Nothing
from appmode.bluetooth.uuids import SPP, UartService
from appmode.errors import AppmodeError

Log = Callable[[str], None]
NOT_PERMITTED = "org.bluez.Error.NotPermitted"

ROOT = "/org/appmode/module"
"""Where the application's objects are exported (one module per process)."""


class Advertisement(ServiceInterface):
    """org.bluez.LEAdvertisement1: connectable, the UART service and the module's name."""

    def __init__(self, name: str, service: str, released: Callable[[], None]) -> None:
        super().__init__("org.bluez.LEAdvertisement1")
        self._name, self._service, self._released = name, service, released

    @dbus_property(access=PropertyAccess.READ)
    def Type(self) -> DBusStr:
        return "peripheral"

    @dbus_property(access=PropertyAccess.READ)
    def ServiceUUIDs(self) -> DBusStrings:
        return [self._service]

    @dbus_property(access=PropertyAccess.READ)
    def LocalName(self) -> DBusStr:
        return self._name

    @dbus_method()
    def Release(self) -> Nothing:
        self._released()


class SerialServer(ServiceInterface):
    """org.bluez.Profile1 in the server role: BlueZ hands each SPP link's socket to
    NewConnection."""

    def __init__(self, connected: Callable[[str, int], None], ended: Callable[[str], None]) -> None:
        super().__init__("org.bluez.Profile1")
        self._connected, self._ended = connected, ended

    @dbus_method()
    def NewConnection(
        self, device: DBusObjectPath, fd: DBusUnixFd, properties: DBusDict
    ) -> Nothing:
        self._connected(device, os.dup(fd))  # dbus-fast closes the one it received

    @dbus_method()
    def RequestDisconnection(self, device: DBusObjectPath) -> Nothing:
        self._ended("the phone closed the link")

    @dbus_method()
    def Release(self) -> Nothing:
        self._ended("BlueZ released the profile")


class AdvertisedModule:
    """The module a phone connects to. `received` gets the bytes the phone sends (after
    the module's input buffer), `left` each link's end; `send` is what the board sends.
    Runs on the event loop that calls `start`."""

    def __init__(
        self,
        name: str,
        service: UartService,
        log: Log,
        received: Callable[[bytes], None],
        left: Callable[[str], None] = lambda why: None,
        admission: Admission = ANY_PHONE,
    ) -> None:
        self.name, self.service, self.admission = name, service, admission
        self._refused: set[str] = set()
        """The phones refused, each said once."""
        self._log, self._received, self._left = log, received, left
        self._holder = ""
        """The device of the phone that holds the BLE link (one at a time, as a module)."""
        self._bus: MessageBus | None = None
        self.adapter = ""
        self._model = ModuleModel()
        self._spp_model = ModuleModel()
        self._spp: socket.socket | None = None
        self._tasks: set[asyncio.Task[None]] = set()
        base = f"{ROOT}/service0"
        self._objects: list[tuple[str, ServiceInterface]] = [
            (base, Service(service.service)),
        ]
        flags = SECURE_FLAGS if admission.secure else []
        self.characteristic = Characteristic(
            service.write, base, self._from_ble, self._subscribed, flags
        )
        self._objects.append((f"{base}/char0", self.characteristic))
        if service.notify != service.write:  # the Nordic UART service: RX and TX
            self.characteristic = Characteristic(
                service.notify, base, self._from_ble, self._subscribed, flags
            )
            self._objects.append((f"{base}/char1", self.characteristic))
        self._advert = Advertisement(name, service.service, self._released)
        self._profile = SerialServer(self._spp_connected, self._spp_ended)

    async def start(self) -> None:
        """Register the application, the advertisement and the SPP server with BlueZ."""
        try:
            bus = await MessageBus(bus_type=BusType.SYSTEM, negotiate_unix_fd=True).connect()
        except Exception as exc:
            raise AppmodeError(explain(exc) or f"cannot reach BlueZ: {exc}") from None
        self._bus = bus
        bus.add_message_handler(self._device_changed)
        self.adapter = await self._find_adapter()
        for path, interface in self._objects:
            bus.export(path, interface)
        bus.export(f"{ROOT}/advertisement", self._advert)
        bus.export(f"{ROOT}/spp", self._profile)
        await self._call(
            self.adapter, "org.bluez.GattManager1", "RegisterApplication", "oa{sv}", [ROOT, {}]
        )
        await self._call(
            self.adapter,
            "org.bluez.LEAdvertisingManager1",
            "RegisterAdvertisement",
            "oa{sv}",
            [f"{ROOT}/advertisement", {}],
        )
        options = {
            "Name": Variant("s", self.name),
            "Role": Variant("s", "server"),
            "Channel": Variant("q", 1),
            "RequireAuthentication": Variant("b", self.admission.secure),
            "RequireAuthorization": Variant("b", False),
        }
        await self._call(
            "/org/bluez",
            "org.bluez.ProfileManager1",
            "RegisterProfile",
            "osa{sv}",
            [f"{ROOT}/spp", SPP, options],
        )
        self._spawn(self._notify())

    async def _find_adapter(self) -> str:
        """The first adapter that serves GATT applications and advertisements."""
        reply = await self._call(
            "/", "org.freedesktop.DBus.ObjectManager", "GetManagedObjects", "", []
        )
        objects: dict[str, dict[str, Any]] = reply.body[0]
        for path, interfaces in sorted(objects.items()):
            if {"org.bluez.GattManager1", "org.bluez.LEAdvertisingManager1"} <= interfaces.keys():
                return path
        raise AppmodeError(
            "no Bluetooth adapter here can advertise a GATT service (BlueZ lists none with "
            "GattManager1 and LEAdvertisingManager1): plug one in, power it on "
            "(bluetoothctl power on), or use BlueZ 5.50 or later"
        )

    async def _call(
        self, path: str, interface: str, member: str, signature: str, body: list[Any]
    ) -> Message:
        """BlueZ's reply; AppmodeError, in a line, if BlueZ cannot be reached or refuses."""
        assert self._bus is not None
        try:
            return await call(self._bus, BLUEZ, path, interface, member, signature, body)
        except DBusError as exc:
            raise AppmodeError(
                explain(exc) or f"BlueZ refused {member}: {exc.type} {exc.text}"
            ) from None
        except Exception as exc:
            raise AppmodeError(explain(exc) or f"BlueZ: {member} failed: {exc}") from None

    def _spawn(self, work: Any) -> None:
        task = asyncio.ensure_future(work)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def stop(self) -> None:
        """Unregister (what a phone still holds is dropped) and leave the bus."""
        self._spp_ended("the module stops")
        if self.characteristic.notifying:
            self.characteristic.set_notifying(False)
        for task in list(self._tasks):
            task.cancel()
        bus = self._bus
        if bus is None or not bus.connected:
            return
        for path, interface, member, body in (
            (
                self.adapter,
                "org.bluez.LEAdvertisingManager1",
                "UnregisterAdvertisement",
                [f"{ROOT}/advertisement"],
            ),
            (self.adapter, "org.bluez.GattManager1", "UnregisterApplication", [ROOT]),
            ("/org/bluez", "org.bluez.ProfileManager1", "UnregisterProfile", [f"{ROOT}/spp"]),
        ):
            with contextlib.suppress(AppmodeError, asyncio.TimeoutError):
                await asyncio.wait_for(self._call(path, interface, member, "o", body), 2.0)
        bus.disconnect()

    # ------------------------------------------------------------ BLE

    def _from_ble(self, data: bytes, device: str) -> None:
        """A phone's write. The first phone to write holds the module until it leaves;
        another's writes are refused (a module takes one link), as are those of a phone
        the admission does not take."""
        if not self.admission.admits(device):
            self._refuse(device, "ble")
            raise DBusError(NOT_PERMITTED, "this phone is not on the module's allow-list")
        if device != "/" and device != self._holder:
            if self._holder:
                raise DBusError(NOT_PERMITTED, "the module is held by another phone")
            self._holder = device
            self._log(f"ble: held by {device}")
            self._spawn(self._watch(device))
        self._received(self._model.from_radio(data, time.monotonic()))

    async def _watch(self, device: str) -> None:
        """Hear BlueZ say the holder's device is no longer connected."""
        assert self._bus is not None
        rule = (
            f"type='signal',sender='{BLUEZ}',interface='org.freedesktop.DBus.Properties',"
            f"member='PropertiesChanged',path='{device}'"
        )
        await add_match(self._bus, rule)

    def _device_changed(self, message: Message) -> bool:
        """The holder's device disconnected (a phone that wrote and never subscribed
        leaves so too)."""
        if (
            message.message_type == MessageType.SIGNAL
            and message.member == "PropertiesChanged"
            and message.path == self._holder
            and message.signature == "sa{sv}as"
            and message.body[0] == "org.bluez.Device1"
            and message.body[1].get("Connected", Variant("b", True)).value is False
        ):
            self._end_ble("the phone disconnected")
        return False

    def _subscribed(self, on: bool) -> None:
        if on:
            self._model = ModuleModel()
            self._log("ble: a phone subscribed to the module's notifications")
        else:  # BlueZ stops the notifications when the central that asked leaves
            self._end_ble("the phone unsubscribed or left")

    def _end_ble(self, why: str) -> None:
        """The BLE link's end: the next phone may hold the module."""
        self._holder = ""
        self._log(f"ble: {why}")
        self._left(f"the phone left the BLE link ({why})")

    def _released(self) -> None:
        self._log("BlueZ released the advertisement: the module is no longer heard")

    async def _notify(self) -> None:
        """Connection events: what the board sent goes out, 20 bytes a notification."""
        while True:
            await asyncio.sleep(CONNECTION_INTERVAL)
            for chunk in self._model.notifications():
                self.characteristic.notify(chunk)

    # ------------------------------------------------------------ SPP

    def _refuse(self, device: str, kind: str) -> None:
        if device not in self._refused:
            self._refused.add(device)
            self._log(f"{kind}: refused {device}: not on the allow-list (--allow)")

    def _spp_connected(self, device: str, fd: int) -> None:
        link = socket.socket(fileno=fd)
        if not self.admission.admits(device):
            link.close()
            self._refuse(device, "spp")
            return
        if self._spp is not None:
            link.close()
            self._log(f"spp: refused a second link from {device}: one link at a time")
            return
        link.setblocking(False)
        self._spp, self._spp_model = link, ModuleModel()
        self._log(f"spp: a phone connected ({device})")
        self._spawn(self._from_spp(link))

    def _spp_ended(self, why: str) -> None:
        link, self._spp = self._spp, None
        if link is not None:
            link.close()
            self._log(f"spp: {why}")
            self._left(f"the phone left the SPP link ({why})")

    async def _from_spp(self, link: socket.socket) -> None:
        async for data in chunks(link):
            self._received(self._spp_model.from_radio(data, time.monotonic()))
        if self._spp is link:
            self._spp_ended("the phone closed the link")

    # ------------------------------------------------------------ the board's bytes

    def send(self, data: bytes) -> None:
        """What the board sends: notified to a subscribed phone, sent on an SPP link."""
        if self.characteristic.notifying:
            self._model.from_uart(data)
        link = self._spp
        if link is not None:
            try:
                link.send(data)
            except BlockingIOError:  # a phone that reads nothing: dropped, as a UART does
                pass
            except OSError as exc:  # the phone closed it before its end was read
                self._spp_ended(f"the link broke ({exc.strerror or exc})")
