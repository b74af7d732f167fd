"""appmode's URL schemes, one table (docs/design.md, "Where a new part goes"): for each, the
module that holds its pyserial port (`protocol_<scheme>`, as pyserial finds handlers:
`serial.serial_for_url("sim://")` opens it in any program that imported appmode; None:
pyserial's own), and what its address is. A scheme is added here and in its module."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType


@dataclass(frozen=True, slots=True)
class Scheme:
    """What a URL scheme is to appmode."""

    port: str | None
    """The module of its port class (`Serial`), which takes the parsed Target itself and
    says what went wrong; None: pyserial opens it from the URL's text."""
    network: bool = False
    """Its address is HOST:PORT over TCP (checked when the URL is parsed)."""
    radio: bool = False
    """Its address is a Bluetooth module's (ports.radio parses it)."""


SCHEMES: Mapping[str, Scheme] = MappingProxyType(
    {
        "sim": Scheme("appmode.ports.protocol_sim"),
        "socket": Scheme("appmode.ports.protocol_tcp", network=True),
        "rfc2217": Scheme(None, network=True),
        "loop": Scheme(None),
        "ble": Scheme("appmode.bluetooth.links.protocol_ble", radio=True),
        "bt": Scheme("appmode.bluetooth.links.protocol_bt", radio=True),
        "zenoh": Scheme("appmode.net.protocol_zenoh"),
    }
)


def handler_packages() -> list[str]:
    """The packages pyserial is to look in for appmode's `protocol_<scheme>` modules, in
    the table's order."""
    found = (s.port.rpartition(".")[0] for s in SCHEMES.values() if s.port is not None)
    return list(dict.fromkeys(found))
