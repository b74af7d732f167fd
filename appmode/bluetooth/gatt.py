"""GATT objects (org.bluez.GattService1, GattCharacteristic1, GattDescriptor1 in BlueZ's
doc/): a UART service whose characteristic takes writes and notifies. `Service` and
`Characteristic` are what an application registers with BlueZ (the advertised module);
`GattService` and `UartCharacteristic` add what BlueZ exports for a connected device's
(the stand-in's view of a module: its device, its handles, the MTU)."""

from __future__ import annotations

from collections.abc import Callable

from dbus_fast import DBusError, Variant
from dbus_fast.annotations import (
    DBusBool,
    DBusBytes,
    DBusDict,
    DBusObjectPath,
    DBusStr,
    DBusUInt16,
)
from dbus_fast.constants import PropertyAccess
from dbus_fast.service import ServiceInterface, dbus_method, dbus_property

from appmode.bluetooth.module import MTU
from appmode.bluetooth.signatures import DBusStrings, Nothing
from appmode.bluetooth.uuids import CCCD

NOT_PERMITTED = "org.bluez.Error.NotPermitted"
FLAGS = ["read", "write-without-response", "write", "notify"]
"""What an HM-10's FFE1 allows (an HC-08's the same)."""


class Service(ServiceInterface):
    """A primary service, as an application registers it."""

    def __init__(self, uuid: str) -> None:
        super().__init__("org.bluez.GattService1")
        self._uuid = uuid

    @dbus_property(access=PropertyAccess.READ)
    def UUID(self) -> DBusStr:
        return self._uuid

    @dbus_property(access=PropertyAccess.READ)
    def Primary(self) -> DBusBool:
        return True


class GattService(Service):
    """A connected device's service, as BlueZ exports it."""

    def __init__(self, uuid: str, device: str, handle: int) -> None:
        super().__init__(uuid)
        self._device, self._handle = device, handle

    @dbus_property(access=PropertyAccess.READ)
    def Device(self) -> DBusObjectPath:
        return self._device

    @dbus_property(access=PropertyAccess.READ)
    def Handle(self) -> DBusUInt16:
        return self._handle


class Characteristic(ServiceInterface):
    """A UART characteristic: writes go to `received`, with the object path of the device
    that wrote ("" when BlueZ does not say); `subscribed` hears StartNotify
    (True) and StopNotify (False); `notify` sends a notification to a subscribed central
    (a PropertiesChanged of Value, as BlueZ relays one)."""

    def __init__(
        self,
        uuid: str,
        service: str,
        received: Callable[[bytes, str], None],
        subscribed: Callable[[bool], None] = lambda on: None,
        secured: list[str] | None = None,
    ) -> None:
        super().__init__("org.bluez.GattCharacteristic1")
        self._uuid, self._service = uuid, service
        self._flags = FLAGS + (secured or [])
        """FLAGS, and what makes BlueZ require pairing (`secured`)."""
        self._received, self._subscribed = received, subscribed
        self._value = b""
        self.notifying = False

    @dbus_property(access=PropertyAccess.READ)
    def UUID(self) -> DBusStr:
        return self._uuid

    @dbus_property(access=PropertyAccess.READ)
    def Service(self) -> DBusObjectPath:
        return self._service

    @dbus_property(access=PropertyAccess.READ)
    def Value(self) -> DBusBytes:
        return self._value

    @dbus_property(access=PropertyAccess.READ)
    def Notifying(self) -> DBusBool:
        return self.notifying

    @dbus_property(access=PropertyAccess.READ)
    def Flags(self) -> DBusStrings:
        return self._flags

    @dbus_method()
    def ReadValue(self, options: DBusDict) -> DBusBytes:
        return self._value

    @dbus_method()
    def WriteValue(self, value: DBusBytes, options: DBusDict) -> Nothing:
        offset = options.get("offset", Variant("q", 0)).value
        if offset:
            raise DBusError("org.bluez.Error.InvalidOffset", "a module takes no offset")
        self._received(bytes(value), str(options.get("device", Variant("o", "/")).value))

    @dbus_method()
    def StartNotify(self) -> Nothing:
        self.set_notifying(True)

    @dbus_method()
    def StopNotify(self) -> Nothing:
        self.set_notifying(False)

    def set_notifying(self, on: bool) -> None:
        """Subscribed or not (a central's request, or its link's end)."""
        if on != self.notifying:
            self.notifying = on
            self.emit_properties_changed({"Notifying": on})
            self._subscribed(on)

    def notify(self, data: bytes) -> None:
        """One notification (at most the MTU's payload), if a central subscribed."""
        self._value = data
        if self.notifying:
            self.emit_properties_changed({"Value": data})


class UartCharacteristic(Characteristic):
    """A connected device's UART characteristic, as BlueZ exports it."""

    def __init__(
        self,
        uuid: str,
        service: str,
        handle: int,
        received: Callable[[bytes, str], None],
        subscribed: Callable[[bool], None] = lambda on: None,
    ) -> None:
        super().__init__(uuid, service, received, subscribed)
        self._handle = handle

    @dbus_property(access=PropertyAccess.READ)
    def Handle(self) -> DBusUInt16:
        return self._handle

    @dbus_property(access=PropertyAccess.READ)
    def MTU(self) -> DBusUInt16:
        return MTU


class Cccd(ServiceInterface):
    """The characteristic's configuration descriptor (bleak lists it; BlueZ writes it)."""

    def __init__(self, characteristic: str, handle: int) -> None:
        super().__init__("org.bluez.GattDescriptor1")
        self._characteristic, self._handle = characteristic, handle

    @dbus_property(access=PropertyAccess.READ)
    def UUID(self) -> DBusStr:
        return CCCD

    @dbus_property(access=PropertyAccess.READ)
    def Characteristic(self) -> DBusObjectPath:
        return self._characteristic

    @dbus_property(access=PropertyAccess.READ)
    def Handle(self) -> DBusUInt16:
        return self._handle

    @dbus_property(access=PropertyAccess.READ)
    def Value(self) -> DBusBytes:
        return b""

    @dbus_property(access=PropertyAccess.READ)
    def Flags(self) -> DBusStrings:
        return ["read", "write"]

    @dbus_method()
    def ReadValue(self, options: DBusDict) -> DBusBytes:
        raise DBusError(NOT_PERMITTED, "BlueZ handles the configuration descriptor itself")
