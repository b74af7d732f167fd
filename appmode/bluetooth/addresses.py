"""What a `ble://` or `bt://` URL names: a device by address (or, on macOS, the UUID the
system gives it), or by advertised name; and, for BLE, the UART service if not a known one."""

from __future__ import annotations

import re
from dataclasses import dataclass
from urllib.parse import parse_qs, unquote, urlsplit

from appmode.bluetooth.uuids import UartService, full

MAC = re.compile(r"^[0-9A-Fa-f]{2}(:[0-9A-Fa-f]{2}){5}$")
DEVICE_UUID = re.compile(r"^[0-9A-Fa-f]{8}-([0-9A-Fa-f]{4}-){3}[0-9A-Fa-f]{12}$")
BLE_USAGE = "ble://AA:BB:CC:DD:EE:FF, ble://UUID (macOS) or ble://NAME[?service=…&write=…&notify=…]"
BT_USAGE = "bt://AA:BB:CC:DD:EE:FF[?channel=N]"
SERVICE_OPTIONS = ("service", "write", "notify")
UUID_TEXT = re.compile(r"^([0-9A-Fa-f]{4}|[0-9A-Fa-f]{8}-([0-9A-Fa-f]{4}-){3}[0-9A-Fa-f]{12})$")


class BadAddress(ValueError):
    """What is wrong with the URL, and how to write it."""


@dataclass(frozen=True, slots=True)
class BleTarget:
    """A BLE module: `address` (a MAC, or macOS's UUID) or `name`, and the UART service
    when the URL names it."""

    address: str | None
    name: str | None
    service: UartService | None

    @property
    def shown(self) -> str:
        return self.address or f"{self.name!r}"


@dataclass(frozen=True, slots=True)
class BtTarget:
    """A classic SPP module by address (`channel` for a direct RFCOMM socket: 1 by default)."""

    address: str
    channel: int


def _parts(url: str, scheme: str, usage: str) -> tuple[str, dict[str, str]]:
    parts = urlsplit(url)
    if parts.scheme.lower() != scheme or not parts.netloc or parts.path not in ("", "/"):
        raise BadAddress(f"expected {usage}, not {url!r}")
    options = {k: v[-1] for k, v in parse_qs(parts.query, keep_blank_values=True).items()}
    return unquote(parts.netloc), options


def parse_ble(url: str) -> BleTarget:
    where, options = _parts(url, "ble", BLE_USAGE)
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
        service = UartService(
            "named", full(options["service"]), full(options["write"]), full(options["notify"])
        )
    if MAC.match(where) or DEVICE_UUID.match(where):
        return BleTarget(where.upper(), None, service)
    return BleTarget(None, where, service)


def parse_bt(url: str) -> BtTarget:
    where, options = _parts(url, "bt", BT_USAGE)
    if not MAC.match(where):
        raise BadAddress(f"{where!r} in {url!r} is not a Bluetooth address: {BT_USAGE}")
    unknown = set(options) - {"channel"}
    if unknown:
        raise BadAddress(f"unknown option {sorted(unknown)[0]!r} in {url!r}: use {BT_USAGE}")
    channel = options.get("channel", "1")
    if not channel.isdigit() or not 1 <= int(channel) <= 30:
        raise BadAddress(f"bad channel {channel!r} in {url!r}: an RFCOMM channel is 1–30")
    return BtTarget(where.upper(), int(channel))


NAME_BYTES = 20
"""The longest name appmode advertises: with the flags and the UART service's 16-bit
UUID it still fits the 31 bytes of an advertising packet (a module's own name is 12)."""


def name_problem(name: str) -> str | None:
    """Why `name` cannot be advertised as a module's name, or None."""
    size = len(name.encode("utf-8"))
    if not name or not name.isprintable():
        return f"{name!r} is not a name to advertise: use printable characters, e.g. HC-08"
    if size > NAME_BYTES:
        return f"{name!r} is {size} bytes; an advertised name fits {NAME_BYTES} at most"
    return None
