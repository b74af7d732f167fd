"""A driving session on a WHEELTEC chassis port: velocity frames in SI from held keys, a
stick, twists and typed commands; the velocity in force sent again every RESEND seconds
while it lasts (a chassis acknowledges nothing, and some firmware never stops by itself);
the status frames shown in SI and given as the car's twist.

It never blocks. Closing sends a zero velocity frame last.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

from appmode.host.chassis.client import RESEND, ChassisHost
from appmode.host.chassis.tokens import parse_token
from appmode.host.events import LinkStatus
from appmode.ports.choice import BoardChoice
from appmode.protocol import chassis
from appmode.protocol.directions import MOTIONS, Motion
from appmode.protocol.sensed import Inertial
from appmode.protocol.twist import Twist
from appmode.session.chassis.commands import COMMANDS, KEYS, KEYS_HELP
from appmode.session.chassis.status import STOP, Keys, chassis_instruments, chassis_rows
from appmode.session.hold import HoldToDrive
from appmode.session.instruments import Instruments
from appmode.session.motion_grid import MotionGridSession
from appmode.session.rows import Row, hold_mode

DEFAULT_SPEED = 300
"""mm/s the keys drive at."""
TURN_RADIUS = 0.5
"""m: the keys turn at speed / TURN_RADIUS rad/s."""
TOP_SPEED = 3000
RESENDING = (
    f"the chassis acknowledges nothing and may never stop by itself: the velocity in "
    f"force is sent again every {RESEND:g} s while it drives, and a zero frame at every end"
)


class ChassisSession(MotionGridSession):
    """A session on a chassis port."""

    host: ChassisHost
    commands = COMMANDS
    keys_help = KEYS_HELP
    keys = KEYS
    hold_keys: ClassVar[dict[str, str]] = {",": "rotate-ccw", ".": "rotate-cw"}
    title = "appmode drive --chassis"

    def __init__(
        self,
        choice: BoardChoice,
        driving: HoldToDrive | None = None,
        record: str | None = None,
        on_message: Callable[[str], None] | None = None,
    ) -> None:
        super().__init__(choice.target, driving, on_message)
        self.host = ChassisHost(choice.target, tap=self._tap, profile=choice.profile)
        spec = choice.profile.chassis
        self.kind = "mec" if spec is None else spec.kind
        self.speed = DEFAULT_SPEED
        self.in_force = STOP
        """The motion a key, a stick or a twist drives, in words, or `stop`."""
        self._booting_said = False
        self._open_recording(record)

    # ------------------------------------------------------------ life cycle

    def start(self) -> None:
        """A zero frame (the car's motion is this session's from now on); the stop guard
        starts watching."""
        self.guard.start()
        self._send(self.host.stop)
        self.say(RESENDING)

    def close(self) -> None:
        """A zero velocity frame last; then the recording."""
        self.guard.close()
        try:
            self._close_link(self.host)
        finally:
            self._drop_recorder()

    def tick(self) -> bool:
        """Read the status frames, send the velocity in force again as it falls due, stop
        a held key that timed out."""
        events = self.host.poll_nowait()
        for event in events:
            if isinstance(event, LinkStatus):
                self.say(f"chassis port: {event.text}")
                if not event.up:
                    self.driving.stop()  # what the car was last told stays in force
            elif isinstance(event, chassis.Status):
                self._flag_stop(event)
        if self.watch():  # first: a stop the guard sent is not sent again
            return True
        if self.driving.release_due(self.now()):
            self.stop()
            return True
        if self.host.connected:
            self._send(self.host.resend)
        return bool(events)

    def _flag_stop(self, status: chassis.Status) -> None:
        if status.flag_stop and self.moving and not self._booting_said:
            self._booting_said = True
            self.say(
                "the board's status says Flag_Stop: it ignores velocity frames until its "
                "start-up has passed (about 10 s after power-up)"
            )

    # ------------------------------------------------------------ what it shows

    def status_rows(self) -> list[Row]:
        return chassis_rows(self.host, self._keys())

    def instruments(self) -> Instruments:
        return chassis_instruments(self.host, self._keys())

    def lit_cell(self) -> tuple[int, int] | None:
        """The cell of the motion the keys drive (none while stopped)."""
        names = self.cell_names()
        cells = [(r, c) for r in range(3) for c in range(3)]
        return next(((r, c) for r, c in cells if names[r][c] == self.in_force), None)

    def _keys(self) -> Keys:
        return Keys(self.in_force, self.speed, TOP_SPEED, hold_mode(self.driving), self.moving)

    def unsaved_warning(self) -> str | None:
        return None  # a chassis port sets nothing

    # ------------------------------------------------------------ the twist sensed

    def odometry_gap(self) -> str | None:
        return None  # every status frame carries the velocity its wheels count

    def sensed(self, after: float) -> list[tuple[float, Twist]]:
        return [(t, status.twist) for t, status in self.host.state.statuses if t > after]

    def inertial(self, after: float) -> list[tuple[float, Inertial]]:
        return [
            (t, Inertial(status.angular_velocity, status.acceleration, status.volts))
            for t, status in self.host.state.statuses
            if t > after
        ]

    # ------------------------------------------------------------ driving

    def _drive_named(self, name: str) -> None:
        self._drive(self._twist_of(MOTIONS[name]), name)

    def steer(self, x: float, y: float) -> None:
        """An analog stick (x right, y forward, each −1…1): forward and sideways on a
        mecanum car, forward and turn on the others; held while it is repeated."""
        if self.link_down():
            return
        self.driving.press("stick", self.now())
        motion = Motion("stick", (x, y, 0.0), (y, x))
        self._drive(self._twist_of(motion), f"stick x {x:+.2f} y {y:+.2f}")

    def _twist_of(self, motion: Motion) -> Twist:
        """A motion of the keys at the keys' speed, as this car's kind drives it."""
        speed = self.speed / chassis.MILLI
        turn = speed / TURN_RADIUS
        x, y, z = motion.holonomic
        if self.kind != "mec" and x and not z:  # sideways: a turn toward that side
            forward, right = motion.differential
            return Twist(forward * speed, 0.0, -right * turn)
        return Twist(y * speed, -x * speed, -z * turn)

    def _move(self, twist: Twist) -> None:
        self._drive(twist, str(twist))

    def _drive(self, twist: Twist, shown: str) -> None:
        if self._send(lambda: self.host.velocity(twist)):
            self.in_force = shown

    def stop(self) -> None:
        """A zero velocity frame."""
        self.driving.stop()
        if self._send(self.host.stop):
            self._forget_motion()

    @property
    def moving(self) -> bool:
        return self.in_force != STOP or self.host.state.in_force is not None

    def _guard_stop(self) -> None:
        self.host.stop()

    def _forget_motion(self) -> None:
        self.driving.stop()
        self.in_force = STOP

    # ------------------------------------------------------------ commands

    def speed_command(self, args: list[str]) -> None:
        """`speed +N`, `speed -N` or `speed N`: the keys' speed in mm/s."""
        self.speed = self._speed_asked(args, TOP_SPEED, " (mm/s)")
        metres = self.speed / chassis.MILLI
        self.say(f"speed {metres:.2f} m/s (turns at {metres / TURN_RADIUS:.2f} rad/s)")

    send_example = "send velocity:0.3,0,0.5 or send stop"

    def _parse_token(self, token: str) -> object:
        """A token as `send --chassis` takes it."""
        return parse_token(token)

    def _perform(self, step: object) -> None:
        assert isinstance(step, (Twist, bytes))
        self.host.send(chassis.command(step) if isinstance(step, Twist) else step)
