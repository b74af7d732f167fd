"""Why Bluetooth cannot be reached here, in one line that says what to do."""

from __future__ import annotations

import os
import sys

from appmode.errors import install_line

STANDIN = "or, with no car, run appmode board --bluetooth and set DBUS_SYSTEM_BUS_ADDRESS"
NO_BLEAK = f"Bluetooth needs the bluetooth extra: {install_line('bluetooth')}"


def no_bluez(reason: str) -> str:
    """BlueZ (Linux) is not there to answer."""
    where = os.environ.get("DBUS_SYSTEM_BUS_ADDRESS")
    bus = f"the bus {where}" if where else "the system bus"
    return (
        f"no Bluetooth here: BlueZ does not answer on {bus} ({reason}); start it "
        f"(sudo systemctl start bluetooth), {STANDIN}"
    )


def explain(exc: BaseException) -> str | None:
    """A one-line reason for a failure to reach the Bluetooth stack, else None."""
    name = type(exc).__name__
    text = str(exc)
    if sys.platform.startswith("linux"):
        if isinstance(exc, (FileNotFoundError, ConnectionRefusedError)):
            return no_bluez("no D-Bus system bus")
        if "ServiceUnknown" in text or "org.bluez was not provided" in text:
            return no_bluez("org.bluez is not on the bus")
        if name == "AuthError":
            return no_bluez("the bus refused us")
    if name == "BleakBluetoothNotAvailableError":
        return f"no Bluetooth here: {text.rstrip('.')}; {STANDIN}"
    return None


def unsupported() -> str | None:
    """Why appmode cannot be a Bluetooth module here (None on Linux, where BlueZ lets a
    program register GATT services, advertisements and SPP servers)."""
    if sys.platform.startswith("linux"):
        return None
    system = "macOS" if sys.platform == "darwin" else "Windows" if os.name == "nt" else sys.platform
    return (
        f"appmode serves as a Bluetooth module through BlueZ, on Linux only, not on {system}: "
        "run it on a Linux machine with an adapter (a Raspberry Pi will do)"
    )
