"""The Serial Port profile through BlueZ's D-Bus API (org.bluez.ProfileManager1 and
org.bluez.Profile1 in BlueZ's doc/): register it, connect it to a device, and take the
file descriptor BlueZ hands to NewConnection."""

from __future__ import annotations

import asyncio
import contextlib
import os
from collections.abc import Callable, Coroutine
from itertools import count
from typing import Any

from dbus_fast import BusType, DBusError, Message, Variant
from dbus_fast.aio import MessageBus
from dbus_fast.annotations import DBusDict, DBusObjectPath, DBusUnixFd
from dbus_fast.service import ServiceInterface, dbus_method
from serial import SerialException

from appmode.bluetooth.calls import BLUEZ, call
from appmode.bluetooth.signatures import Nothing
from appmode.bluetooth.uuids import SPP
from appmode.ports.radio import BtTarget

PAIR = (
    "pair it once (bluetoothctl: scan on, pair {0}, trust {0}; the PIN is usually 1234), then retry"
)
_numbers = count()


class SerialProfile(ServiceInterface):
    """Our org.bluez.Profile1: BlueZ calls NewConnection with the connected socket."""

    def __init__(self) -> None:
        super().__init__("org.bluez.Profile1")
        self.connection: asyncio.Future[int] = asyncio.get_running_loop().create_future()

    @dbus_method()
    def NewConnection(
        self, device: DBusObjectPath, fd: DBusUnixFd, properties: DBusDict
    ) -> Nothing:
        mine = os.dup(fd)  # dbus-fast closes the one it received
        if self.connection.done():
            os.close(mine)
        else:
            self.connection.set_result(mine)

    @dbus_method()
    def RequestDisconnection(self, device: DBusObjectPath) -> Nothing:
        """The socket's end tells the port."""

    @dbus_method()
    def Release(self) -> Nothing:
        """BlueZ is going away: the socket's end tells the port."""


async def _call(
    bus: MessageBus,
    path: str,
    interface: str,
    member: str,
    signature: str = "",
    body: list[Any] | None = None,
) -> Message:
    return await call(bus, BLUEZ, path, interface, member, signature, body)


async def devices(bus: MessageBus) -> dict[str, dict[str, Variant]]:
    """BlueZ's devices (their org.bluez.Device1 properties) by object path; OSError (with
    the bus's error name) when BlueZ does not answer."""
    try:
        reply = await _call(bus, "/", "org.freedesktop.DBus.ObjectManager", "GetManagedObjects")
    except DBusError as exc:
        raise OSError(f"{exc.type}: {exc.text}") from None
    return {
        str(path): interfaces["org.bluez.Device1"]
        for path, interfaces in reply.body[0].items()
        if "org.bluez.Device1" in interfaces
    }


async def _device(bus: MessageBus, address: str) -> str:
    for path, device in (await devices(bus)).items():
        if str(device["Address"].value).upper() == address:
            if not device["Paired"].value:
                raise SerialException(f"{address} is not paired: {PAIR.format(address)}")
            return str(path)
    raise SerialException(f"BlueZ does not know {address}: {PAIR.format(address)}")


async def connect_spp(
    target: BtTarget, timeout: float
) -> tuple[int, Callable[[], Coroutine[object, object, None]]]:
    """A connected SPP socket's descriptor, and what ends the connection."""
    bus = await MessageBus(bus_type=BusType.SYSTEM, negotiate_unix_fd=True).connect()
    profile = SerialProfile()
    path = f"/org/appmode/spp{os.getpid()}_{next(_numbers)}"
    registered = False
    device = ""

    async def end() -> None:
        with contextlib.suppress(DBusError):  # already gone: nothing left to end
            if device:
                await _call(bus, device, "org.bluez.Device1", "DisconnectProfile", "s", [SPP])
            if registered:
                await _call(
                    bus, "/org/bluez", "org.bluez.ProfileManager1", "UnregisterProfile", "o", [path]
                )
        bus.disconnect()

    try:
        device_path = await _device(bus, target.address)
        bus.export(path, profile)
        options = {"Role": Variant("s", "client"), "Name": Variant("s", "appmode")}
        try:
            await _call(
                bus,
                "/org/bluez",
                "org.bluez.ProfileManager1",
                "RegisterProfile",
                "osa{sv}",
                [path, SPP, options],
            )
        except DBusError as exc:
            raise OSError(f"{exc.type}: {exc.text}") from None
        registered = True
        try:
            await _call(bus, device_path, "org.bluez.Device1", "ConnectProfile", "s", [SPP])
        except DBusError as exc:
            why = exc.text or exc.type
            raise SerialException(
                f"cannot connect to {target.address} ({why}): switch the car on and bring "
                "it in range; a phone still connected to it keeps it: disconnect the phone"
            ) from None
        device = device_path
        fd = await asyncio.wait_for(profile.connection, timeout)
    except BaseException:
        await end()
        raise
    return fd, end
