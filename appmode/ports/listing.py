"""The serial ports of this machine (pyserial's list_ports), and which look like a car's
link: a USB-UART adapter, or a Bluetooth serial port."""

from __future__ import annotations

from dataclasses import dataclass

from serial.tools import list_ports

ADAPTERS: dict[tuple[int, int], str] = {
    (0x1A86, 0x7523): "CH340 USB-UART",
    (0x1A86, 0x5523): "CH341 USB-UART",
    (0x1A86, 0x55D4): "CH9102 USB-UART",
    (0x10C4, 0xEA60): "CP210x USB-UART",
    (0x0403, 0x6001): "FTDI FT232R USB-UART",
    (0x0403, 0x6015): "FTDI FT231X USB-UART",
    (0x067B, 0x2303): "PL2303 USB-UART",
}
"""USB vendor and product ids of the adapters these boards are wired to."""

BLUETOOTH_HINTS = ("rfcomm", "bluetooth", "-serialport", "hc-05", "hc-06")
"""Names of Bluetooth serial ports: Linux rfcomm, macOS /dev/tty.NAME-SerialPort."""


@dataclass(frozen=True, slots=True)
class Device:
    """A serial device the system lists, and what it looks like."""

    device: str
    description: str
    hwid: str
    kind: str
    """What it looks like: an adapter's name, "Bluetooth serial", or ""."""


def kind_of(device: str, description: str, vid: int | None, pid: int | None) -> str:
    if vid is not None and pid is not None and (vid, pid) in ADAPTERS:
        return ADAPTERS[vid, pid]
    text = f"{device} {description}".lower()
    if any(hint in text for hint in BLUETOOTH_HINTS):
        return "Bluetooth serial"
    return ""


def serial_ports() -> list[Device]:
    """Every serial port pyserial finds, likely links first, then by device name."""
    found = [
        Device(
            info.device,
            info.description if info.description != "n/a" else "",
            info.hwid if info.hwid != "n/a" else "",
            kind_of(info.device, info.description or "", info.vid, info.pid),
        )
        for info in list_ports.comports(include_links=True)
    ]
    return sorted(found, key=lambda p: (not p.kind, p.device))
