"""The host over a WHEELTEC chassis port (docs/protocol.md §15): velocity frames in SI out,
status frames in.

The board acknowledges nothing and some firmware never stops by itself, so a host that
drives re-sends the velocity in force (`resend`, at RESEND) while motion lasts, and
closing sends a zero frame last; with `confirm_stop` it then waits for a status frame
that shows the car at rest, sending the zero frame again meanwhile (a frame a bad byte
spoilt is dropped without a word).
"""

from __future__ import annotations

import math
from functools import partial

from appmode.board.profiles import Profile, profile_named
from appmode.errors import AppmodeError
from appmode.host.chassis.state import ChassisState
from appmode.host.events import LinkStatus
from appmode.host.link import Link, Opener
from appmode.line.wire import CHASSIS, CHASSIS_BAUD, Tap
from appmode.ports.target import AnyTarget, as_target
from appmode.ports.urls import open_link
from appmode.protocol import chassis
from appmode.protocol.twist import Twist

RESEND = 0.1
"""Seconds between frames of the velocity in force (10 Hz, as ROS drivers send cmd_vel):
well within F1's 1 s time-out, and what keeps a car that never times out on a leash."""
SETTLE = 2.0
"""Seconds a closing host waits for a status frame that shows the car at rest."""
AGAIN = 0.2
"""Seconds between the zero frames sent while it waits."""
OPEN_CHASSIS = partial(open_link, baud=CHASSIS_BAUD)

Event = chassis.Status | chassis.Junk


def chassis_target(url: AnyTarget) -> AnyTarget:
    """The chassis port of `url`: a sim:// URL without `port=` opens its board's."""
    target = as_target(url)
    if not target.simulated or "port" not in target.options:
        return target.on_port(CHASSIS) if target.simulated else target
    if target.sim_port != CHASSIS:
        raise AppmodeError(
            f"{target} is the simulated board's {target.sim_port} port: --chassis speaks the "
            "chassis port's frames; use port=chassis or leave port= out"
        )
    return target


class ChassisHost(Link[Event]):
    """A session with one board's chassis port."""

    sent = "c>"
    received = "c<"

    def __init__(
        self,
        url: AnyTarget,
        tap: Tap | None = None,
        opener: Opener = OPEN_CHASSIS,
        stop_on_close: bool = True,
        profile: Profile | None = None,
        confirm_stop: bool = False,
    ) -> None:
        super().__init__(chassis_target(url), tap, opener)
        self.stop_on_close = stop_on_close
        self.profile = profile or profile_named("wheeltec-mec")
        self.state = ChassisState()
        self.confirm_stop = confirm_stop
        self.notes: list[str] = []
        """What closing had to do beyond its stop, for people."""

    def _on_lost(self) -> None:
        self.state.reset_decoder()

    def _sent(self, data: bytes) -> None:
        self.state.sent(data, self.now())

    def _read_once(self, block: bool) -> list[Event | LinkStatus]:
        new: list[Event | LinkStatus] = list(self._take_pending())
        data = self._read_bytes(block and not new)
        new += self._take_pending()
        if data:
            new += self.state.feed(data, self.now())
        return new

    def velocity(self, twist: Twist, mode: int = chassis.NORMAL) -> bytes:
        """Send a velocity frame of `twist`; the bytes sent."""
        frame = chassis.command(twist, mode)
        self.send(frame)
        return frame

    def stop(self) -> bytes:
        """The zero velocity frame, now."""
        self.send(chassis.STOP)
        return chassis.STOP

    def resend_due(self) -> float:
        """When the velocity in force is next sent again (session time; infinity: none is
        in force)."""
        state = self.state
        if state.in_force is None or state.sent_at is None:
            return math.inf
        return state.sent_at + RESEND

    def resend(self) -> bool:
        """The velocity in force again when RESEND has passed since the last frame;
        whether one went out."""
        frame = self.state.in_force
        if frame is None or self.now() < self.resend_due():
            return False
        self.send(frame.raw)
        return True

    @property
    def telemetry(self) -> None:
        """No APP records come here."""
        return None

    def in_force_text(self) -> str | None:
        """What the car was last told to do on this port, in words (None: stop)."""
        frame = self.state.in_force
        return None if frame is None else str(frame)

    def _stop(self) -> bytes:
        return chassis.STOP

    def _before_stop(self) -> None:
        if self.confirm_stop:
            self.poll_nowait()  # frames from before the stop must not confirm it

    def _confirm(self) -> None:
        """With `confirm_stop`, once the board has sent status frames: wait for one that
        shows the car at rest, the zero frame sent again every AGAIN seconds."""
        if not self.confirm_stop or self.state.status is None:
            return
        start = last = self.now()
        while self.now() - start < SETTLE:
            for event in self.poll(AGAIN / 4):
                if isinstance(event, chassis.Status) and event.twist.still:
                    return
            if self.now() - last >= AGAIN:
                last = self.now()
                self.send(chassis.STOP)
        moving = self.state.status
        shown = "" if moving is None else f" ({moving.twist})"
        raise AppmodeError(
            f"the car's status frames still showed motion {SETTLE:g} s after the zero "
            f"frame{shown}: it may not have stopped; check it"
        )
