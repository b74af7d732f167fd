"""Which phones an advertised module takes (`--allow`, `--secure`): a module on the air
takes any central in range unless told otherwise, and a stranger's phone can then drive
the car. No D-Bus here: the command line reads it before Bluetooth is loaded."""

from __future__ import annotations

import re
from dataclasses import dataclass

SECURE_FLAGS = ["encrypt-authenticated-read", "encrypt-authenticated-write"]
"""A characteristic's flags that make BlueZ require an authenticated pairing (bonding)
before a phone may read or write it."""
ADDRESS = re.compile(r"[0-9A-F]{2}(:[0-9A-F]{2}){5}")


@dataclass(frozen=True)
class Admission:
    """Which phones the module takes: with `allow`, only those addresses (any other's
    writes and links are refused); with `secure`, only a phone paired and bonded with
    this machine (BlueZ asks for it before the first write)."""

    allow: frozenset[str] = frozenset()
    secure: bool = False

    def admits(self, device: str) -> bool:
        """Whether the phone at `device` (BlueZ's object path, `…/dev_AA_BB_…`) may
        write."""
        address = device.rsplit("/dev_", 1)[-1].replace("_", ":").upper()
        return not self.allow or address in self.allow

    def warning(self, name: str) -> str | None:
        """What a user must be told when any phone in range may drive the car."""
        if self.allow or self.secure:
            return None
        return (
            f"WARNING: the module {name} takes any phone in range (no pairing, no "
            "allow-list): a stranger's phone can drive this car. --allow ADDRESS takes "
            "only those phones; --secure takes only phones paired with this machine"
        )


ANY_PHONE = Admission()
"""What a module takes unless told otherwise: any phone in range."""


def addresses(text: str) -> str:
    """An argparse type: a Bluetooth address, AA:BB:CC:DD:EE:FF."""
    address = text.strip().upper()
    if not ADDRESS.fullmatch(address):
        raise ValueError(f"{text!r} is not a Bluetooth address such as 02:CA:40:00:00:01")
    return address
