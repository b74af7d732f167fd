"""The adapter and the devices BlueZ exports (org.bluez.Adapter1, org.bluez.Device1 in
BlueZ's doc/), as the stand-in serves them. What they do is the stand-in's (`Radio`)."""

from __future__ import annotations

from typing import Protocol

from dbus_fast.annotations import (
    DBusBool,
    DBusDict,
    DBusInt16,
    DBusObjectPath,
    DBusStr,
    DBusUInt32,
)
from dbus_fast.constants import PropertyAccess
from dbus_fast.service import ServiceInterface, dbus_method, dbus_property

from appmode.bluetooth.signatures import DBusStrings, Nothing

ADAPTER = "/org/bluez/hci0"
FILTERS = ["UUIDs", "RSSI", "Pathloss", "Transport", "DuplicateData", "Discoverable", "Pattern"]


class Radio(Protocol):
    """What the adapter and devices ask of the stand-in."""

    async def connect(self, device: Device, uuid: str | None) -> None: ...
    def disconnect(self, device: Device) -> None: ...


def device_path(address: str) -> str:
    return f"{ADAPTER}/dev_{address.replace(':', '_')}"


class Adapter(ServiceInterface):
    """The adapter; StartDiscovery and StopDiscovery, which need the caller's bus name
    (each client has its own discovery session), are the stand-in's."""

    def __init__(self, radio: Radio, address: str) -> None:
        super().__init__("org.bluez.Adapter1")
        self._radio, self._address = radio, address
        self.discovering = False

    @dbus_property(access=PropertyAccess.READ)
    def Address(self) -> DBusStr:
        return self._address

    @dbus_property(access=PropertyAccess.READ)
    def AddressType(self) -> DBusStr:
        return "public"

    @dbus_property(access=PropertyAccess.READ)
    def Name(self) -> DBusStr:
        return "appmode-standin"

    @dbus_property(access=PropertyAccess.READ)
    def Alias(self) -> DBusStr:
        return "appmode-standin"

    @dbus_property(access=PropertyAccess.READ)
    def Powered(self) -> DBusBool:
        return True

    @dbus_property(access=PropertyAccess.READ)
    def PowerState(self) -> DBusStr:
        return "on"

    @dbus_property(access=PropertyAccess.READ)
    def Discoverable(self) -> DBusBool:
        return False

    @dbus_property(access=PropertyAccess.READ)
    def Pairable(self) -> DBusBool:
        return True

    @dbus_property(access=PropertyAccess.READ)
    def Discovering(self) -> DBusBool:
        return self.discovering

    @dbus_property(access=PropertyAccess.READ)
    def UUIDs(self) -> DBusStrings:
        return []

    @dbus_property(access=PropertyAccess.READ)
    def Roles(self) -> DBusStrings:
        return ["central", "peripheral"]

    @dbus_method()
    def SetDiscoveryFilter(self, properties: DBusDict) -> Nothing:
        """Taken and ignored: the stand-in's one BLE module matches any filter bleak sets."""

    @dbus_method()
    def GetDiscoveryFilters(self) -> DBusStrings:
        return FILTERS

    @dbus_method()
    def RemoveDevice(self, device: DBusObjectPath) -> Nothing:
        """Forgetting the simulated car changes nothing: it is found again."""

    def set_discovering(self, on: bool) -> None:
        if on != self.discovering:
            self.discovering = on
            self.emit_properties_changed({"Discovering": on})


class Device(ServiceInterface):
    """A nearby module: `le` (a BLE UART module, found by discovery) or `classic` (an SPP
    module, paired and trusted as `bluetoothctl pair` leaves it)."""

    def __init__(
        self, radio: Radio, address: str, name: str, uuids: list[str], *, le: bool
    ) -> None:
        super().__init__("org.bluez.Device1")
        self._radio = radio
        self.address, self.label, self.le = address, name, le
        self.path = device_path(address)
        self.uuids = uuids
        self.connected = False
        self.resolved = False
        self.rssi = -58
        self.paired = self.trusted = not le
        """Classic modules come paired (`bluetoothctl pair`); a BLE one once Pair is called."""

    @dbus_property(access=PropertyAccess.READ)
    def Address(self) -> DBusStr:
        return self.address

    @dbus_property(access=PropertyAccess.READ)
    def AddressType(self) -> DBusStr:
        return "public"

    @dbus_property(access=PropertyAccess.READ)
    def Name(self) -> DBusStr:
        return self.label

    @dbus_property(access=PropertyAccess.READ)
    def Alias(self) -> DBusStr:
        return self.label

    @dbus_property(access=PropertyAccess.READ)
    def Class(self) -> DBusUInt32:
        return 0 if self.le else 0x1F00  # uncategorised, as HC-05s report

    @dbus_property(access=PropertyAccess.READ)
    def Paired(self) -> DBusBool:
        return self.paired

    @dbus_property(access=PropertyAccess.READ)
    def Bonded(self) -> DBusBool:
        return self.paired

    @dbus_property()
    def Trusted(self) -> DBusBool:
        return self.trusted

    @Trusted.setter  # type: ignore[no-redef]  # dbus-fast's property setter
    def Trusted(self, value: DBusBool) -> None:
        """Set by a central before it pairs (bleak does)."""
        self.trusted = value

    @dbus_property(access=PropertyAccess.READ)
    def Blocked(self) -> DBusBool:
        return False

    @dbus_property(access=PropertyAccess.READ)
    def LegacyPairing(self) -> DBusBool:
        return not self.le  # a PIN (1234), not Secure Simple Pairing

    @dbus_property(access=PropertyAccess.READ)
    def RSSI(self) -> DBusInt16:
        return self.rssi

    @dbus_property(access=PropertyAccess.READ)
    def Connected(self) -> DBusBool:
        return self.connected

    @dbus_property(access=PropertyAccess.READ)
    def ServicesResolved(self) -> DBusBool:
        return self.resolved

    @dbus_property(access=PropertyAccess.READ)
    def UUIDs(self) -> DBusStrings:
        return self.uuids

    @dbus_property(access=PropertyAccess.READ)
    def Adapter(self) -> DBusObjectPath:
        return ADAPTER

    @dbus_method()
    async def Connect(self) -> Nothing:
        await self._radio.connect(self, None)

    @dbus_method()
    async def ConnectProfile(self, uuid: DBusStr) -> Nothing:
        await self._radio.connect(self, uuid.lower())

    @dbus_method()
    def Disconnect(self) -> Nothing:
        self._radio.disconnect(self)

    @dbus_method()
    def DisconnectProfile(self, uuid: DBusStr) -> Nothing:
        self._radio.disconnect(self)

    @dbus_method()
    def Pair(self) -> Nothing:
        """Paired and bonded at once (Just Works: no passkey to confirm); already, for a
        classic module."""
        if not self.paired:
            self.paired = True
            self.emit_properties_changed({"Paired": True, "Bonded": True})

    @dbus_method()
    def CancelPairing(self) -> Nothing:
        """Nothing is under way."""

    def set_state(self, connected: bool) -> None:
        """Connected (and, on BLE, services resolved) or not, as BlueZ announces it."""
        changed: dict[str, object] = {}
        if connected != self.connected:
            self.connected = changed["Connected"] = connected
        if self.le and connected != self.resolved:
            self.resolved = changed["ServicesResolved"] = connected
        if changed:
            self.emit_properties_changed(changed)

    def advertise(self, rssi: int) -> None:
        """One advertisement heard while discovering (bleak's scanner sees RSSI change)."""
        self.rssi = rssi
        self.emit_properties_changed({"RSSI": rssi})
