"""A driving session on the control port (UART2): velocity frames from held keys, turns
in angle mode, the ten settings by name, the encoder report; with `app_url`, the APP
port of the same board alongside (its records shown, both ports recorded).

It never blocks: reads and sets run as queries (`control_query`) whose outcome arrives
with `tick()`. Closing sends the zero velocity frame last on UART2.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import ClassVar

from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.host.app.state import HostState
from appmode.host.control.client import ControlHost
from appmode.host.control.query import ROTATE_POLL, ReadDone, rotation_done
from appmode.host.control.state import PortMode
from appmode.host.control.tokens import Step, parse_token, perform
from appmode.host.events import BoardWarning, LinkStatus
from appmode.host.outcomes import QueryFailed
from appmode.ports.choice import BoardChoice
from appmode.protocol import control, param_values, params, settings
from appmode.protocol.directions import MOTIONS, Motion
from appmode.protocol.params import DriveType
from appmode.protocol.sensed import signs_in_force
from appmode.protocol.twist import Twist
from appmode.session.control.commands import COMMANDS, KEYS, KEYS_HELP, SETTING_NAMES
from appmode.session.control.motion import velocity_for
from appmode.session.control.status import (
    STOP,
    Keys,
    control_instruments,
    control_lit,
    control_rows,
)
from appmode.session.control.velocity import frame_fields
from appmode.session.hold import HoldToDrive
from appmode.session.instruments import Instruments
from appmode.session.motion_grid import MotionGridSession
from appmode.session.rows import Row, hold_mode

DEFAULT_SPEED = 300
"""Velocity units (omni, mecanum) or tenths of a percent of duty (diff types)."""
DEFAULT_ANGLE = 90.0
REPORT_BIT = params.MODE_BIT["encoder_report"]

NO_READS = (
    "this board answers no reads (the reference firmware; see appmode protocol 13): its "
    "settings and wheels are not shown, and its velocities are not limited to max_speed"
)


class ControlSession(MotionGridSession):
    """A session on the control port, with the APP port of the same board if given."""

    host: ControlHost
    commands = COMMANDS
    keys_help = KEYS_HELP
    keys = KEYS
    hold_keys: ClassVar[dict[str, str]] = {",": "rotate-ccw", ".": "rotate-cw"}

    def __init__(
        self,
        choice: BoardChoice,
        driving: HoldToDrive | None = None,
        record: str | None = None,
        on_message: Callable[[str], None] | None = None,
    ) -> None:
        super().__init__(choice.target, driving, on_message)
        self.reads = choice.profile.answers_reads
        """The board answers reads (the reference firmware does not: §13)."""
        self.host = ControlHost(
            choice.target, tap=self._tap, profile=choice.profile, drive=choice.drive
        )
        self.app: Host | None = None
        if choice.app is not None:
            try:
                self.app = Host(choice.app, tap=self._tap, profile=choice.profile)
            except BaseException:
                self.host.close()
                raise
        self.speed = DEFAULT_SPEED
        self.angle = DEFAULT_ANGLE
        self.in_force = STOP
        """The motion a key or `drive` is driving, or `stop` (frames sent otherwise show
        as the host's frame in force)."""
        self.rotation: tuple[float, float] | None = None
        """A turn under way: (when it started, degrees)."""
        self._next_angle_read = 0.0
        self.baseline: dict[str, int] | None = None
        """The settings as first read, or as last saved: what a quit would keep."""
        self._open_recording(record)

    @property
    def drive(self) -> DriveType | None:
        return self.host.known_drive

    # ------------------------------------------------------------ life cycle

    def start(self) -> None:
        """Take the motion over with the zero velocity frame, then read the settings
        (the encoder report is turned on for the session once system_mode is known); the
        stop guard starts watching."""
        self.guard.start()
        self._send(lambda: self.host.stop())
        if self.reads:
            self.query(SETTING_NAMES)
        else:
            self.say(NO_READS)

    def close(self) -> None:
        """`Z` on the APP port, then on UART2 the encoder report as it was and the zero
        velocity frame last; then the recording."""
        self.guard.close()
        try:
            if self.app is not None:
                self.app.close()
        finally:
            try:
                self._close_link(self.host)
            finally:
                self._drop_recorder()

    # ------------------------------------------------------------ time

    def tick(self) -> bool:
        """Read both ports, end queries, follow a turn, stop a held key that timed out."""
        events: list[object] = list(self.host.poll_nowait())
        for event in events:
            if isinstance(event, LinkStatus):
                self.say(f"UART2: {event.text}")
                if not event.up:
                    self.driving.stop()  # what the car was last told stays in force
            elif isinstance(event, PortMode):
                self.say(f"UART2: {event.text}")
                if not event.app:  # a reset, or cleared from the APP port
                    self.baseline = None  # the encoder report is off again: turn it on
                    self.query(SETTING_NAMES, quiet=True)
            elif isinstance(event, ReadDone):
                self._done(event)
            elif isinstance(event, QueryFailed):
                self.fail(event.text)
                self.rotation = None
        if self.app is not None:
            for app_event in self.app.poll_nowait():
                events.append(app_event)
                if isinstance(app_event, LinkStatus):
                    self.say(f"APP port: {app_event.text}")
                elif isinstance(app_event, BoardWarning):
                    self.say(f"WARNING: {app_event.text}")
        self._follow_rotation()
        if self.watch():  # first: a stop the guard sent is not sent again
            return True
        if self.driving.release_due(self.now()):
            self.stop()
            return True
        return bool(events)

    def _done(self, outcome: ReadDone) -> None:
        values = outcome.values
        if self.rotation is not None and set(values) == {"pending_angle"}:
            self._rotation_read(values["pending_angle"])
            return
        self.say(outcome.text if len(values) < len(SETTING_NAMES) else "settings read")
        if set(SETTING_NAMES) <= set(values) and self.baseline is None:
            self.baseline = self._comparable(values)
            self._report_on(values["system_mode"])

    def _report_on(self, mode: int) -> None:
        """Turn the encoder report on for the session (put back when it closes)."""
        if mode & REPORT_BIT:
            return
        self.host.put_back_on_close("system_mode", mode)
        self.say("turning the encoder report on for this session (system_mode bit 6)")
        self.query(change=("system_mode", mode | REPORT_BIT), quiet=True)

    def _follow_rotation(self) -> None:
        if self.rotation is None or self.busy or self.now() < self._next_angle_read:
            return
        self._next_angle_read = self.now() + ROTATE_POLL
        self.query(["pending_angle"], quiet=True)

    def _rotation_read(self, left: int) -> None:
        assert self.rotation is not None
        started, degrees = self.rotation
        try:
            done = rotation_done(left, self.now() - started)
        except AppmodeError as exc:
            self.fail(str(exc))
            self.stop()
            return
        if done:
            self.rotation = None
            self.say(f"rotated {degrees:g}° in {self.now() - started:.2f} s")

    # ------------------------------------------------------------ what it shows

    title = "appmode drive --uart2"

    def status_rows(self) -> list[Row]:
        return control_rows(self.host, self.app, self._keys())

    def lit_cell(self) -> tuple[int, int] | None:
        return control_lit(self.cell_names(), self._keys())

    def _keys(self) -> Keys:
        return Keys(
            self.in_force,
            self.rotation,
            self.speed,
            self.top_speed(),
            self.angle,
            hold_mode(self.driving),
            self.moving,
            tuple(self.unsaved()),
            self.drive,
        )

    # ------------------------------------------------------------ driving

    def _drive_named(self, name: str) -> None:
        drive = self.drive
        if drive is None:
            self.driving.stop()
            self.say("the drive type is not known yet: reading system_mode (or use --drive-type)")
            if not self.busy:
                self.query(["system_mode"])
            return
        self._drive_fields(velocity_for(MOTIONS[name], self.speed, drive), name)

    def steer(self, x: float, y: float) -> None:
        """An analog stick (x right, y forward, each −1…1): a velocity frame of the
        speed scaled by how far it is pushed. It lasts while it is held (repeated)."""
        if self.link_down():
            return
        self.driving.press("stick", self.now())  # a stick that is let go stops the car
        drive = self.drive
        if drive is None:
            self._drive_named("forward")  # says the drive type is being read, and reads it
            return
        motion = Motion("stick", (x, y, 0.0), (y, x))
        self._drive_fields(velocity_for(motion, self.speed, drive), f"stick x {x:+.2f} y {y:+.2f}")

    def telemetry_state(self) -> HostState | None:
        """The APP port's state beside, when it is open (its records drawn as waves)."""
        return None if self.app is None else self.app.state

    def _move(self, twist: Twist) -> None:
        """A velocity frame of `twist`; while the drive type is unknown, it is read."""
        drive = self.drive
        if drive is None:
            self._say_once("the drive type is not known yet: reading system_mode")
            if not self.busy and self.reads:
                self.query(["system_mode"], quiet=True)
            return
        max_speed = self.host.state.values.get("max_speed")
        try:
            fields = frame_fields(twist, drive, self.host.profile.velocity_si, max_speed)
        except ValueError as exc:
            self._say_once(f"not driven: {exc}")
            return
        self._drive_fields(fields, str(twist))

    def _signs(self) -> tuple[float, float, float] | None:
        """The signs of the frame in force, which the firmware applies as sent (§13.1)."""
        turning = self.rotation is not None
        return None if turning else signs_in_force(self.host.state.in_force, self.drive)

    def _drive_fields(self, fields: dict[str, int], shown: str) -> None:
        """A velocity frame of `fields` (`ControlHost.velocity`'s), shown as `shown`."""
        if self._send(lambda: self.host.velocity(**fields)):
            self.in_force = shown
            self.rotation = None

    def stop(self) -> None:
        """The zero velocity frame (it also drops a pending turn)."""
        self.driving.stop()
        if self._send(lambda: self.host.stop()):
            self._forget_motion()

    @property
    def moving(self) -> bool:
        """A key's motion, a turn, a frame or (APP mode, §12) a letter is in force."""
        state = self.host.state
        frame, letter = state.in_force, state.letter
        return self.in_force != STOP or self.rotation is not None or (frame or letter) is not None

    def _guard_stop(self) -> None:
        self.host.stop()

    def _forget_motion(self) -> None:
        self.driving.stop()
        self.in_force = STOP
        self.rotation = None

    def rotate(self, degrees: float) -> None:
        if self.drive is DriveType.DIFF_GYRO:
            raise AppmodeError("a diff-gyro car has no angle mode (§9.1): drive with , and .")
        if self.drive is None:
            raise AppmodeError("the drive type is not known yet: try again, or use --drive-type")
        self.driving.stop()
        if self._send(lambda: self.host.start_rotation(degrees)):
            self.in_force = STOP
            self.rotation = (self.now(), degrees)
            self._next_angle_read = self.now() + ROTATE_POLL
            self.say(f"rotating {degrees:g}°")

    # ------------------------------------------------------------ settings

    def query(
        self,
        names: Iterable[str] = (),
        change: tuple[str, int] | None = None,
        quiet: bool = False,
    ) -> None:
        """Start a read or a verified set (`ControlHost.new_query`) unless one runs."""
        if self.busy:
            if not quiet:
                self.say("busy: a read or set is in progress")
            return
        self.host.start_query(self.host.new_query(names, change))

    def set_setting(self, name: str, value: int) -> None:
        """A verified set; in APP mode (§12) only system_mode, as the APP frame `{8:…}`,
        verified by reading it back once bit 7 is off."""
        if not self.host.state.app_mode:
            self.query(change=(name, value))
        elif self._send(lambda: self.host.set_in_app_mode(name, value)):
            self.say(f"sent {{8:{value}}} (APP mode: the port reads APP frames)")
            if not self.host.state.app_mode:
                self.query(["system_mode"])

    def parameters(self) -> dict[str, int | float]:
        """Settings 1–9 as last read: the APP port's nine parameters."""
        values = self.host.state.values
        return {
            spec.name: param_values.user_number(spec, values[spec.name])
            for spec in self.parameter_specs()
            if spec.name in values
        }

    def set_parameter(self, name: str, value: str) -> None:
        if not self.reads:
            raise AppmodeError(f"a set cannot be verified: {NO_READS}")
        specs = param_values.SHEET
        index = param_values.lookup(specs, name)
        number = param_values.from_user(specs[index], value)
        param_values.check(specs, index, number)
        self.set_setting(specs[index].name, number)

    def parameter_specs(self) -> param_values.Specs:
        return param_values.SHEET if self.reads else ()

    def store(self, op: str) -> None:
        if not self._send(lambda: self.host.store(op)):
            return
        meaning = settings.STORE_BY_NAME[op].meaning
        if op == "save":
            values = self.host.state.values
            if set(SETTING_NAMES) <= set(values):
                self.baseline = self._comparable(values)
            self.say(f"sent save: {meaning} (the board sends no reply)")
        else:
            self.say(f"sent {op}: {meaning}; reading the settings")
            self.query(SETTING_NAMES, quiet=True)

    def unsaved_warning(self) -> str | None:
        if self.baseline is None:
            return None
        now = self._comparable(self.host.state.values)
        changed = [f"{name} {self.baseline[name]} → {now[name]}" for name in self.unsaved()]
        return f"not saved: {', '.join(changed)}" if changed else None

    def unsaved(self) -> list[str]:
        """The settings changed since they were read or saved."""
        if self.baseline is None:
            return []
        now = self._comparable(self.host.state.values)
        return [
            name
            for name in SETTING_NAMES
            if name in now and name in self.baseline and now[name] != self.baseline[name]
        ]

    def instruments(self) -> Instruments:
        return control_instruments(self.host, self.app, self._keys())

    @staticmethod
    def _comparable(values: dict[str, int]) -> dict[str, int]:
        """The settings as a save keeps them: system_mode's bits 6 and 7 are not saved."""
        kept = {name: values[name] for name in SETTING_NAMES if name in values}
        if "system_mode" in kept:
            kept["system_mode"] &= ~(REPORT_BIT | params.MODE_BIT["app_mode"])
        return kept

    # ------------------------------------------------------------ commands

    def speed_command(self, args: list[str]) -> None:
        """`speed +N`, `speed -N` or `speed N`: the speed the keys drive at."""
        top = self.top_speed()
        self.speed = self._speed_asked(args, top)
        unit = (
            "‰ duty"
            if top == control.MAX_DUTY
            else " (velocity units; the board caps at max_speed)"
        )
        self.say(f"speed {self.speed}{unit}")

    def top_speed(self) -> int:
        """The largest speed: a duty's ‰ on a differential car, else the frame's limit."""
        differential = self.drive is not None and self.drive.differential
        return control.MAX_DUTY if differential else control.U16

    send_example = "send velocity:0,200,0 or send FFFE01…"

    def _parse_token(self, token: str) -> object:
        """A token as `send --uart2` takes it: a frame by name, or raw hex."""
        return parse_token(token)

    def _perform(self, step: object) -> None:
        assert isinstance(step, (Step, bytes))
        perform(self.host, step)
