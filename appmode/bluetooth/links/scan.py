"""The phone app's list of nearby cars: BLE modules heard advertising (bleak), paired
classic modules (BlueZ's devices on Linux; the system's /dev/cu.* ports on macOS), each
with the URL that drives it."""

from __future__ import annotations

import asyncio
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

from appmode.bluetooth.uuids import SPP, uart_service
from appmode.ports.listing import serial_ports

MODULE_NAMES = ("HC-", "HM-", "JDY", "BT05", "CC41", "MLT-BT05", "BT04", "SPP-CA", "WHEELTEC")
"""Names the car's modules ship with (a module found by name may hide its service)."""
STEP = 0.25


@dataclass(frozen=True, slots=True)
class Found:
    """One nearby (or paired) module."""

    kind: str
    """ble, spp (a paired classic module), or port (macOS: its serial port)."""
    name: str
    address: str
    rssi: int | None
    """Signal strength in dBm (BLE, heard now); None: paired, not heard."""
    service: str
    """The UART service (FFE0, Nordic UART), SPP, or "" (none appmode knows)."""
    url: str

    @property
    def likely(self) -> bool:
        """A car's module, by its service or its name."""
        return bool(self.service) or self.name.upper().startswith(MODULE_NAMES)

    def as_json(self) -> dict[str, Any]:
        return asdict(self)


Progress = Callable[[float, int], None]
"""Told the seconds scanned and how many were found so far."""


async def scan_ble(seconds: float, progress: Progress) -> list[Found]:
    """BLE devices heard within `seconds`, by signal strength."""
    from bleak import BleakScanner

    scanner = BleakScanner()
    start = time.monotonic()
    await scanner.start()
    try:
        while (elapsed := time.monotonic() - start) < seconds:
            progress(elapsed, len(scanner.discovered_devices_and_advertisement_data))
            await asyncio.sleep(min(STEP, seconds - elapsed))
    finally:
        await scanner.stop()
    found = []
    for device, adv in scanner.discovered_devices_and_advertisement_data.values():
        service = uart_service(adv.service_uuids)
        found.append(
            Found(
                "ble",
                adv.local_name or device.name or "",
                device.address,
                adv.rssi,
                service.name if service else "",
                f"ble://{device.address}",
            )
        )
    return sorted(found, key=lambda f: -(f.rssi or -999))


async def paired_spp() -> list[Found]:
    """Paired classic devices that offer SPP: BlueZ's (Linux), the system's ports (macOS)."""
    if sys.platform == "darwin":
        return [
            Found("port", p.device.rsplit(".", 1)[-1], p.device, None, "SPP", p.device)
            for p in serial_ports()
            if p.device.startswith("/dev/cu.") and p.kind == "Bluetooth serial"
        ]
    if not sys.platform.startswith("linux"):
        return []
    from dbus_fast import BusType
    from dbus_fast.aio import MessageBus

    from appmode.bluetooth.links.serial_port_profile import devices

    bus = await MessageBus(bus_type=BusType.SYSTEM).connect()
    try:
        known = await devices(bus)
    finally:
        bus.disconnect()
    found = []
    for device in known.values():
        if not device["Paired"].value:
            continue
        uuids = device.get("UUIDs")
        if uuids is None or SPP not in [str(u).lower() for u in uuids.value]:
            continue
        address = str(device["Address"].value)
        name = str(device["Alias"].value) if "Alias" in device else address
        found.append(Found("spp", name, address, None, "SPP", f"bt://{address}"))
    return found


async def scan(seconds: float, progress: Progress) -> list[Found]:
    """Every module near or paired: BLE by signal strength, then the paired ones."""
    paired = await paired_spp()
    heard = await scan_ble(seconds, progress)
    return heard + [p for p in paired if p.address not in {h.address for h in heard}]
