"""A driving session opened from a board choice: the one place a view (the console, the
page, a test) gets its session."""

from __future__ import annotations

from collections.abc import Callable

from appmode.line.wire import APP, CHASSIS, UART2
from appmode.ports.choice import BoardChoice
from appmode.session.app.session import AppSession
from appmode.session.base import BaseSession
from appmode.session.chassis.session import ChassisSession
from appmode.session.control.session import ControlSession
from appmode.session.hold import HoldToDrive

SESSIONS: dict[str, type[AppSession] | type[ControlSession] | type[ChassisSession]] = {
    APP: AppSession,
    UART2: ControlSession,
    CHASSIS: ChassisSession,
}
"""The session of each port a board choice drives (`BoardChoice.port`)."""


def open_session(
    choice: BoardChoice,
    driving: HoldToDrive | None = None,
    on_message: Callable[[str], None] | None = None,
    record: str | None = None,
) -> BaseSession:
    """The session `choice` asks for: the APP port's, the control port's (with the APP
    port of the same board beside it) or the chassis port's; `record` names its
    recording."""
    return SESSIONS[choice.port](choice, driving, record, on_message)
