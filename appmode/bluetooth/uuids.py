"""The Bluetooth numbers appmode knows: the UART services of the car's modules, the Serial
Port profile, and the module names the vendor's app lists (one table, read by the links,
`scan` and the stand-in)."""

from __future__ import annotations

from dataclasses import dataclass

from appmode.ports.radio import full

SPP = "00001101-0000-1000-8000-00805f9b34fb"
"""The Serial Port profile (HC-05, HC-06, JDY-31 and the classic side of a JDY-33)."""
CCCD = "00002902-0000-1000-8000-00805f9b34fb"
"""The client characteristic configuration descriptor (notifications on/off)."""


@dataclass(frozen=True, slots=True)
class UartService:
    """A BLE "transparent UART": bytes written to `write` go out of the module's UART, and
    what its UART receives is notified on `notify`."""

    name: str
    service: str
    write: str
    notify: str


UART_SERVICES = (
    UartService("FFE0", full("ffe0"), full("ffe1"), full("ffe1")),
    # HM-10, HC-08, JDY-08/10, BT05, CC41, and the BLE side of a JDY-33
    UartService(
        "Nordic UART",
        "6e400001-b5a3-f393-e0a9-e50e24dcca9e",
        "6e400002-b5a3-f393-e0a9-e50e24dcca9e",
        "6e400003-b5a3-f393-e0a9-e50e24dcca9e",
    ),
)


def uart_service(uuids: list[str] | tuple[str, ...]) -> UartService | None:
    """The first known UART service among `uuids` (a device's advertised or found ones)."""
    have = {u.lower() for u in uuids}
    return next((s for s in UART_SERVICES if s.service in have), None)
