"""Driving sessions as the commands open them: a URL (and its options) chosen once, then
`open_session`."""

from __future__ import annotations

from collections.abc import Callable

from appmode.ports.choice import choose
from appmode.ports.target import parse_target
from appmode.session.base import BaseSession
from appmode.session.hold import HoldToDrive
from appmode.session.opener import open_session


def session(
    url: str,
    driving: HoldToDrive | None = None,
    record: str | None = None,
    *,
    uart2: bool = False,
    url2: str | None = None,
    profile: str | None = None,
    drive: str | None = None,
    on_message: Callable[[str], None] | None = None,
) -> BaseSession:
    """The session `appmode drive URL [URL2] [--uart2] [--profile] [--drive]` opens."""
    choice = choose(
        parse_target(url),
        None if url2 is None else parse_target(url2),
        uart2=uart2,
        profile=profile,
        drive=drive,
    )
    return open_session(choice, driving, on_message, record)
