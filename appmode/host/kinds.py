"""The host of each of a board's ports, by the port's name: the one table a program
that opens a board's ports side by side reads (`net.share`), as
`ports.choice.BoardChoice.ports` names them."""

from __future__ import annotations

from collections.abc import Callable

from appmode.host.app.client import Host
from appmode.host.chassis.client import ChassisHost
from appmode.host.control.client import ControlHost
from appmode.line.wire import APP, CHASSIS, UART2, Tap
from appmode.ports.choice import BoardChoice
from appmode.ports.target import Target

AnyHost = Host | ControlHost | ChassisHost
HOSTS: dict[str, Callable[[Target, BoardChoice, Tap | None], AnyHost]] = {
    APP: lambda target, choice, tap: Host(target, tap=tap, profile=choice.profile),
    UART2: lambda target, choice, tap: ControlHost(
        target, tap=tap, profile=choice.profile, drive=choice.drive
    ),
    CHASSIS: lambda target, choice, tap: ChassisHost(target, tap=tap, profile=choice.profile),
}
"""How each port's host is opened, for the board `choice` names."""


def open_hosts(choice: BoardChoice, tap: Callable[[str], Tap]) -> dict[str, AnyHost]:
    """A host of each of the ports `choice` opens, by name (`tap(name)` hears its
    bytes); all closed again when one cannot open."""
    hosts: dict[str, AnyHost] = {}
    try:
        for name, target in choice.ports().items():
            hosts[name] = HOSTS[name](target, choice, tap(name))
    except BaseException:
        for host in hosts.values():
            host.close()
        raise
    return hosts
