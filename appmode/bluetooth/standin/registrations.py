"""What a program registers with BlueZ to serve (a GATT application, an advertisement,
an SPP server), as the stand-in keeps it (`Peer`), and the adapter's two manager
interfaces as BlueZ lists them."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from dbus_fast.annotations import DBusByte, DBusUInt16
from dbus_fast.constants import PropertyAccess
from dbus_fast.service import ServiceInterface, dbus_property

from appmode.bluetooth.gatt import UartCharacteristic
from appmode.bluetooth.signatures import DBusStrings
from appmode.bluetooth.standin.devices import Device

GATT = "org.bluez.GattManager1"
ADVERTISING = "org.bluez.LEAdvertisingManager1"


class GattManager(ServiceInterface):
    """org.bluez.GattManager1 as the adapter lists it; its calls, which need the
    caller's bus name, are answered by `peers.Peers.handle`."""

    def __init__(self) -> None:
        super().__init__(GATT)


class AdvertisingManager(ServiceInterface):
    """org.bluez.LEAdvertisingManager1 as the adapter lists it (calls: `peers.Peers.handle`)."""

    def __init__(self, active: Callable[[], int]) -> None:
        super().__init__(ADVERTISING)
        self._active = active

    @dbus_property(access=PropertyAccess.READ)
    def ActiveInstances(self) -> DBusByte:
        return self._active()

    @dbus_property(access=PropertyAccess.READ)
    def SupportedInstances(self) -> DBusByte:
        return 4

    @dbus_property(access=PropertyAccess.READ)
    def SupportedIncludes(self) -> DBusStrings:
        return ["tx-power", "appearance", "local-name"]

    @dbus_property(access=PropertyAccess.READ)
    def MaxAdvLen(self) -> DBusUInt16:
        return 31


@dataclass
class Peer:
    """What one bus client registered: a GATT application, an advertisement, an SPP
    server; and the devices a central sees for them."""

    sender: str
    application: str = ""
    services: dict[str, str] = field(default_factory=dict)
    """The application's service paths and UUIDs."""
    characteristics: dict[str, tuple[str, str]] = field(default_factory=dict)
    """The application's characteristic paths, each with its UUID and service path."""
    secured: set[str] = field(default_factory=set)
    """The characteristics whose flags ask for an encrypted, authenticated link: BlueZ
    takes a central's writes to them only once it is paired."""
    advertisement: str = ""
    name: str = ""
    service_uuids: list[str] = field(default_factory=list)
    spp_server: str = ""
    ble: Device | None = None
    spp: Device | None = None
    proxies: dict[str, UartCharacteristic] = field(default_factory=dict)
    """The central's view of each application characteristic, by the application's path."""
    exported: list[str] = field(default_factory=list)
