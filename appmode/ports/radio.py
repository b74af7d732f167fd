"""What a `ble://` or `bt://` URL names, with no I/O: a device by address (or, on macOS,
the UUID the system gives it) or by advertised name, and, for BLE, the UART service if
not a known one; a classic module's RFCOMM channel. `target.parse_target` reads them
once; the Bluetooth ports (bluetooth/) open what they name."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

MAC = re.compile(r"^[0-9A-Fa-f]{2}(:[0-9A-Fa-f]{2}){5}$")
DEVICE_UUID = re.compile(r"^[0-9A-Fa-f]{8}-([0-9A-Fa-f]{4}-){3}[0-9A-Fa-f]{12}$")
BLE_USAGE = "ble://AA:BB:CC:DD:EE:FF, ble://UUID (macOS) or ble://NAME[?service=…&write=…&notify=…]"
BT_USAGE = "bt://AA:BB:CC:DD:EE:FF[?channel=N]"
SERVICE_OPTIONS = ("service", "write", "notify")
UUID_TEXT = re.compile(r"^([0-9A-Fa-f]{4}|[0-9A-Fa-f]{8}-([0-9A-Fa-f]{4}-){3}[0-9A-Fa-f]{12})$")


class BadAddress(ValueError):
    """What is wrong with the URL, and how to write it."""


def full(short: str) -> str:
    """A 16-bit UUID (`ffe0`) as the 128-bit one BlueZ and bleak name it."""
    return f"0000{short.lower()}-0000-1000-8000-00805f9b34fb" if len(short) == 4 else short.lower()


@dataclass(frozen=True, slots=True)
class BleTarget:
    """A BLE module: `address` (a MAC, or macOS's UUID) or `name`, and the UART service
    (service, write and notify UUIDs) when the URL names it."""

    address: str | None
    name: str | None
    service: tuple[str, str, str] | None

    @property
    def shown(self) -> str:
        return self.address or f"{self.name!r}"


@dataclass(frozen=True, slots=True)
class BtTarget:
    """A classic SPP module by address (`channel` for a direct RFCOMM socket: 1 by default)."""

    address: str
    channel: int


def parse_ble(where: str, options: Mapping[str, str], url: str) -> BleTarget:
    """A `ble://` URL's address part and options (`url` is what messages quote)."""
    if not where:
        raise BadAddress(f"expected {BLE_USAGE}, not {url!r}")
    unknown = set(options) - set(SERVICE_OPTIONS)
    if unknown:
        raise BadAddress(
            f"unknown option {sorted(unknown)[0]!r} in {url!r}: use service, write, notify"
        )
    service = None
    if options:
        missing = [name for name in SERVICE_OPTIONS if name not in options]
        if missing:
            raise BadAddress(f"{url!r} names a service: give {', '.join(missing)} too")
        bad = [v for v in options.values() if not UUID_TEXT.match(v)]
        if bad:
            raise BadAddress(f"{bad[0]!r} in {url!r} is not a UUID (ffe0, or 128-bit)")
        service = (full(options["service"]), full(options["write"]), full(options["notify"]))
    if MAC.match(where) or DEVICE_UUID.match(where):
        return BleTarget(where.upper(), None, service)
    return BleTarget(None, where, service)


def parse_bt(where: str, options: Mapping[str, str], url: str) -> BtTarget:
    """A `bt://` URL's address part and options (`url` is what messages quote)."""
    if not where:
        raise BadAddress(f"expected {BT_USAGE}, not {url!r}")
    if not MAC.match(where):
        raise BadAddress(f"{where!r} in {url!r} is not a Bluetooth address: {BT_USAGE}")
    unknown = set(options) - {"channel"}
    if unknown:
        raise BadAddress(f"unknown option {sorted(unknown)[0]!r} in {url!r}: use {BT_USAGE}")
    channel = options.get("channel", "1")
    if not channel.isdigit() or not 1 <= int(channel) <= 30:
        raise BadAddress(f"bad channel {channel!r} in {url!r}: an RFCOMM channel is 1–30")
    return BtTarget(where.upper(), int(channel))
