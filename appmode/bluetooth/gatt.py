"""The GATT objects BlueZ exports for a connected BLE module (org.bluez.GattService1,
GattCharacteristic1, GattDescriptor1 in BlueZ's doc/), as the stand-in serves them: one
UART service whose characteristic takes writes and notifies what the board sends."""

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


class GattService(ServiceInterface):
    def __init__(self, uuid: str, device: str, handle: int) -> None:
        super().__init__("org.bluez.GattService1")
        self._uuid, self._device, self._handle = uuid, device, handle

    @dbus_property(access=PropertyAccess.READ)
    def UUID(self) -> DBusStr:
        return self._uuid

    @dbus_property(access=PropertyAccess.READ)
    def Primary(self) -> DBusBool:
        return True

    @dbus_property(access=PropertyAccess.READ)
    def Device(self) -> DBusObjectPath:
        return self._device

    @dbus_property(access=PropertyAccess.READ)
    def Handle(self) -> DBusUInt16:
        return self._handle


class UartCharacteristic(ServiceInterface):
    """Writes go to `received`; `notify` sends what the board sent to subscribed centrals
    (a PropertiesChanged of Value, as BlueZ relays a notification)."""

    def __init__(
        self, uuid: str, service: str, handle: int, received: Callable[[bytes], None]
    ) -> None:
        super().__init__("org.bluez.GattCharacteristic1")
        self._uuid, self._service, self._handle = uuid, service, handle
        self._received = received
        self._value = b""
        self.notifying = False

    @dbus_property(access=PropertyAccess.READ)
    def UUID(self) -> DBusStr:
        return self._uuid

    @dbus_property(access=PropertyAccess.READ)
    def Service(self) -> DBusObjectPath:
        return self._service

    @dbus_property(access=PropertyAccess.READ)
    def Handle(self) -> DBusUInt16:
        return self._handle

    @dbus_property(access=PropertyAccess.READ)
    def Value(self) -> DBusBytes:
        return self._value

    @dbus_property(access=PropertyAccess.READ)
    def Notifying(self) -> DBusBool:
        return self.notifying

    @dbus_property(access=PropertyAccess.READ)
    def Flags(self) -> DBusStrings:
        return FLAGS

    @dbus_property(access=PropertyAccess.READ)
    def MTU(self) -> DBusUInt16:
        return MTU

    @dbus_method()
    def ReadValue(self, options: DBusDict) -> DBusBytes:
        return self._value

    @dbus_method()
    def WriteValue(self, value: DBusBytes, options: DBusDict) -> Nothing:
        offset = options.get("offset", Variant("q", 0)).value
        if offset:
            raise DBusError("org.bluez.Error.InvalidOffset", "a module takes no offset")
        self._received(bytes(value))

    @dbus_method()
    def StartNotify(self) -> Nothing:
        if not self.notifying:
            self.notifying = True
            self.emit_properties_changed({"Notifying": True})

    @dbus_method()
    def StopNotify(self) -> Nothing:
        if self.notifying:
            self.notifying = False
            self.emit_properties_changed({"Notifying": False})

    def notify(self, data: bytes) -> None:
        """One notification (at most the MTU's payload), if a central subscribed."""
        self._value = data
        if self.notifying:
            self.emit_properties_changed({"Value": data})


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
