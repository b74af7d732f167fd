"""A driving session opened from a board choice: the one place a view (the console, the
page, a test) gets its session."""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from appmode.line.wire import APP, CHASSIS, UART2
from appmode.ports.choice import BoardChoice
from appmode.protocol.channels import Viewer
from appmode.protocol.layouts import Layout
from appmode.protocol.params import DriveType
from appmode.session.app.session import AppSession
from appmode.session.base import BaseSession
from appmode.session.chassis.session import ChassisSession
from appmode.session.control.session import ControlSession
from appmode.session.desk import Desk
from appmode.session.hold import HoldToDrive

SESSIONS: dict[str, type[AppSession] | type[ControlSession] | type[ChassisSession]] = {
    APP: AppSession,
    UART2: ControlSession,
    CHASSIS: ChassisSession,
}
"""The session of each port a board choice drives (`BoardChoice.port`)."""


class LiveViewer(Viewer, Protocol):
    """A live view (`viewers.live.LiveView`) whose viewers may drive and tune the car
    through its `desk`, if it has one."""

    desk: Desk | None


MakeView = Callable[[Layout, DriveType | None], LiveViewer | None]
"""Makes the live view of a board whose records are of a layout (and whose drive type
is known, or None): `cli.live_view.LiveViews.make`; None if none was asked for."""


def open_session(
    choice: BoardChoice,
    driving: HoldToDrive | None = None,
    on_message: Callable[[str], None] | None = None,
    record: str | None = None,
    view: MakeView | None = None,
) -> BaseSession:
    """The session `choice` asks for: the APP port's, the control port's (with the APP
    port of the same board beside it) or the chassis port's; `record` names its
    recording; `view` makes the live view (for the board's layout and drive type) that
    is shown the session, whose viewers drive and tune where it lets them."""
    shown = None if view is None else view(choice.profile.a_layout, choice.known_drive)
    session = SESSIONS[choice.port](choice, driving, record, on_message)
    if shown is not None:
        session.add_viewer(shown)
        if shown.desk is not None:
            session.desks.append(shown.desk)
    return session
