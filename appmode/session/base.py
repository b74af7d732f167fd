"""What every driving session shares, whatever port it drives: messages, recording,
hold-to-drive, the stop authority, the twist (`move`, in SI, which each port translates;
`sensed`, what the records show) and the command line. Each port's session is in its
folder: `app/` (the APP port), `control/` (UART2), `chassis/` (WHEELTEC's chassis port).
"""

from __future__ import annotations

import shlex
import time
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

from appmode.board.profiles import board_line
from appmode.errors import AppmodeError
from appmode.host import signals
from appmode.host.link import UNDELIVERED, Link
from appmode.ports.recording import open_recorder
from appmode.ports.target import Target
from appmode.protocol.channels import Viewer
from appmode.protocol.profile_file import ParamSpec
from appmode.protocol.recorder import Recorder
from appmode.protocol.sensed import Inertial
from appmode.protocol.twist import Twist
from appmode.session import sensing
from appmode.session.authority import LAPSE, StopGuard
from appmode.session.command_line import (
    COMMON,
    COMMON_ALIASES,
    LOG,
    MAX_COMMAND,
    CommandSpec,
    Step,
    help_lines,
)
from appmode.session.hold import TWIST, HoldToDrive
from appmode.writer import CLOSE_WAIT

if TYPE_CHECKING:
    from appmode.host.app.client import Host
    from appmode.host.app.state import HostState
    from appmode.host.chassis.client import ChassisHost
    from appmode.host.control.client import ControlHost
    from appmode.session.desk import Desk
    from appmode.session.instruments import Instruments
    from appmode.session.rows import Row


class BaseSession(ABC):
    """A console session: what it shows (messages), what it records, how it drives."""

    commands: tuple[CommandSpec[Any], ...] = ()
    """The session's own commands (COMMON follows them)."""
    aliases: ClassVar[dict[str, str]] = {}
    """Other names for its commands."""
    keys_help = ""
    """Its keys, as the panel and help show them."""
    keys: ClassVar[dict[str, str]] = {}
    """Keys that run a command line."""
    hold_keys: ClassVar[dict[str, str]] = {}
    """Driving keys besides the grid: what `press` takes for each."""
    waveforms = False
    """Whether the panel can show waveforms (key v)."""

    def __init__(
        self,
        target: Target,
        driving: HoldToDrive | None,
        on_message: Callable[[str], None] | None,
    ) -> None:
        self.target = target
        self.url = self.target.url
        self.driving = driving or HoldToDrive()
        self.messages: deque[str] = deque(maxlen=LOG)
        self._down_said = False  # "link is down" said in this outage
        self.failures = 0
        """Commands and queries that failed (`fail`)."""
        self.on_message = on_message
        self.recorder: Recorder | None = None
        self.viewers: list[Viewer] = []
        """Live views beside the session's own (`--foxglove`): each a tap that never
        blocks (`viewers.live.LiveView`)."""
        self.desks: list[Desk] = []
        """What viewers that may drive and tune ask (`--foxglove-drive`), served at each tick."""
        self.names_files = True
        """The command line may name files (`record FILE`); a page's may not: its
        recordings go to `recordings_folder()` under names appmode makes."""
        self.recording_failure: str | None = None
        """Why a recording stopped on its own (the command then exits non-zero)."""
        specs: tuple[CommandSpec[Any], ...] = (*self.commands, *COMMON)
        self._specs = {spec.name: spec for spec in specs}
        self.completions: dict[str, object] = {spec.name: spec.completes for spec in specs}
        """Every command's name, and what the command line completes after it."""
        self.help_lines = tuple(help_lines(specs, self.keys_help))
        """The commands, a line each, then the keys (made once: shown at every redraw)."""
        self.closing_notes: list[str] = []
        """What closing had to do beyond its stop, for people (shown after the console)."""
        self.undelivered: str | None = None
        """Set when the session ended with its link down, so that its stop was never sent:
        what to tell people (the view prints it and exits non-zero when `left_moving`)."""
        self.left_moving = False
        """The car was last told to move when the final stop could not be delivered."""
        self.lease: float | None = None
        """Seconds motion lasts without `keepalive` (None: the view's ticks prove it alive)."""
        self.lease_source = "the page"
        """What proves the motion alive, as messages name it (`cmd_vel` for a ROS node)."""
        self._alive_at = 0.0
        self._quiet_said = False
        self._said: set[str] = set()
        self.guard = StopGuard(self._stoppable, self._guard_stop, self._lapsed)
        """The stop authority's thread: stops the car when the ticks stall."""

    # ------------------------------------------------------------ what a session is

    host: Host | ControlHost | ChassisHost
    """The host that drives (its clock is the session's)."""

    @property
    def simulated(self) -> bool:
        """The board is the simulated one (here, or shared from another machine)."""
        return self.target.simulated or getattr(self.host.link, "simulated", False) is True

    def now(self) -> float:
        """Seconds since the session started."""
        return self.host.now()

    @property
    def busy(self) -> bool:
        """A read or set is under way (script mode waits for it)."""
        return self.host.state.query is not None

    @abstractmethod
    def start(self) -> None:
        """Put the board in a known, stopped state and read its values."""

    @abstractmethod
    def close(self) -> None:
        """Stop the car (the protocol's stop is the last thing sent) and close all."""

    @abstractmethod
    def tick(self) -> bool:
        """Read what arrived and let time pass; whether anything happened."""

    @abstractmethod
    def press(self, key: str) -> None:
        """A held driving key (what it drives, as the session names it)."""

    @abstractmethod
    def grid_key(self, row: int, col: int) -> str:
        """What `press` takes for a key of the 3×3 grid (row 0 is the front)."""

    @abstractmethod
    def stop(self) -> None:
        """Stop the car now."""

    @property
    @abstractmethod
    def moving(self) -> bool:
        """Whether motion is in force, whatever started it (key, command, stick, bytes, turn)."""

    def move(self, twist: Twist, source: str = TWIST, timeout: float | None = None) -> None:
        """Drive `twist` (SI units, REP 103) for as long as its source repeats it: each
        call keeps it alive as a held key's repeats do (and `keepalive`, where a lease
        is set, must come too; a program's twist never latches, a typed one as a key
        does); a still twist stops the car. Every port takes it (the APP port as its nearest
        direction and speed). `timeout`: how long a call keeps it alive, if not hold's."""
        if twist.still:
            if self.moving:
                self.stop()
            return
        if self.link_down():
            return
        self.driving.press(source, self.now(), timeout)
        self._move(twist)

    @abstractmethod
    def _move(self, twist: Twist) -> None:
        """Send what drives `twist` on this port (it is held: `move`)."""

    def _say_once(self, text: str) -> None:
        """Say `text` the first time only (for what a stream of twists would repeat)."""
        if text not in self._said:
            self._said.add(text)
            self.say(text)

    @abstractmethod
    def _guard_stop(self) -> None:
        """Send the port's stop and nothing else (from the stop guard's thread)."""

    @abstractmethod
    def _forget_motion(self) -> None:
        """The car was stopped another way: nothing is in force any more."""

    def _close_link(self, link: Link[Any]) -> None:
        """Close the driving link (its stop last); note a stop that could not be sent."""
        moving = self.moving
        if link.close() is not None or not link.stop_on_close or link.stopped_far:
            return
        self.left_moving = moving
        self.undelivered = (
            f"{UNDELIVERED} (the link to {self.url} is down and the firmware has no "
            "time-out: stop it by hand, or reconnect and stop it)"
            if moving
            else f"the final stop was not delivered (the link to {self.url} is down); the "
            "last command the car got was a stop"
        )

    # ------------------------------------------------------------ the stop authority

    def _stoppable(self) -> bool:
        """Motion is in force and a stop can go out now (a link down stops when back)."""
        return self.moving and self.host.connected

    def keepalive(self) -> None:
        """The motion's source proves it is alive (a page's heartbeat)."""
        self._alive_at = self.now()
        self._quiet_said = False

    def watch(self) -> bool:
        """At each tick: end motion whose source has gone quiet (`lease`), and take note
        of a stop the guard sent (the ticks stalled, or the source went quiet while the
        session could not tick); whether the car was stopped. Viewers' requests first."""
        for desk in self.desks:
            desk.serve(self)
        if self.guard.beat():
            self._forget_motion()
            if self.guard.why and not self.moving:
                self.say(f"stopped: {self.guard.why}")
            return True
        if self.lease is None or not self.moving or not self.host.connected:
            return False  # a link that is down sends its stop first when it is back
        quiet = self.now() - self._alive_at
        if quiet <= self.lease:
            return False
        self.stop()
        if not self._quiet_said:
            self._quiet_said = True
            self.say(f"stopped: no heartbeat from {self.lease_source} for {quiet:.2f} s")
        return True

    def _lapsed(self) -> str | None:
        """For the stop guard's thread: what to say when the motion's source (a held key's
        repeats, "": let go; a page's heartbeats) is over LAPSE late, untaken; else None."""
        now = self.now()
        late = self.driving.late(now)
        if late is not None and late > LAPSE:
            return ""
        if self.lease is not None and (quiet := now - self._alive_at) > self.lease + LAPSE:
            return f"no heartbeat from {self.lease_source} for {quiet:.2f} s"
        return None

    def steer(self, x: float, y: float) -> None:
        """An analog stick (x right, y forward, each −1…1), where the port takes one."""
        raise AppmodeError("this port takes no analog steering: drive with the pad")

    title: ClassVar[str] = "appmode drive"
    """What a view calls the session."""

    @abstractmethod
    def status_rows(self) -> list[Row]:
        """What the session shows now, row by row (the key grid apart)."""

    @abstractmethod
    def instruments(self) -> Instruments:
        """What the session shows now, as values for a page's instruments."""

    @abstractmethod
    def grid_cells(self) -> list[list[str]]:
        """The 3×3 grid (row 0 is the front): what each key does, as shown."""

    @abstractmethod
    def cell_names(self) -> list[list[str]]:
        """What each key of the grid does, by name (`forward`, `rotate-cw`, `stop`)."""

    @abstractmethod
    def lit_cell(self) -> tuple[int, int] | None:
        """The cell of the grid in force (the car moves), if any."""

    def telemetry_state(self) -> HostState | None:
        """The APP port's state, whose A and B records a view may draw as waveforms."""
        return None

    # ------------------------------------------------------------ the twist sensed

    def odometry_gap(self) -> str | None:
        """Why `sensed` gives nothing on this session (None: it gives the car's twist)."""
        return sensing.gap(self.telemetry_state(), self._signs() is not None)

    def sensed(self, after: float) -> list[tuple[float, Twist]]:
        """The car's twist as each A record since `after` (session s) shows it, in order."""
        state = self.telemetry_state()
        return [] if state is None else sensing.twists(state, self._signs, after)

    def inertial(self, after: float) -> list[tuple[float, Inertial]]:
        """The IMU's own readings since `after`, in time order (a chassis port's)."""
        return []

    def _signs(self) -> tuple[float, float, float] | None:
        """The signs of x, y and z the motion in force drives, where the port knows them
        as the board applies them (the control port's frames); None elsewhere."""
        return None

    def parameters(self) -> dict[str, int | float]:
        """The car's parameters as last read, in the user's units (none: not yet, or none)."""
        return {}

    def set_parameter(self, name: str, value: str) -> None:
        """Set a parameter (`value` in the user's units), verified by reading back."""
        raise AppmodeError("this port has no parameters to set")

    def parameter_specs(self) -> tuple[ParamSpec, ...]:
        """The parameters `parameters` names: their ranges and scales (none: none)."""
        return ()

    @abstractmethod
    def unsaved_warning(self) -> str | None:
        """What was set in this session and not saved since, in a line; None if nothing."""

    # ------------------------------------------------------------ messages

    def link_down(self) -> bool:
        """Whether the link is down, said once an outage (keys repeat many times a second)."""
        if self.host.connected:
            self._down_said = False
            return False
        if not self._down_said:
            self._down_said = True
            self.say("link is down: not driving")
        return True

    def fail(self, text: str) -> None:
        """Say what went wrong, and count it (script mode's exit status)."""
        self.failures += 1
        self.say(f"error: {text}")

    def say(self, text: str) -> None:
        self.messages.append(text)
        for viewer in self.viewers:
            viewer.note(text)
        if self.on_message is not None:
            self.on_message(text)

    # ------------------------------------------------------------ recording

    def _open_recording(self, record: str | None) -> None:
        """Start the recording asked for on the command line; on failure close the
        session (its stop is sent) and raise."""
        if not record:
            return
        try:
            self.start_recording(record, origin=0.0)  # from the session's start
        except BaseException:
            self.close()
            raise

    def add_viewer(self, viewer: Viewer) -> None:
        """Show the session to `viewer` from now on (its bytes, what it says), on the
        session's clock from `viewer.epoch`, the wall-clock time of its start."""
        viewer.epoch = time.time() - self.now()
        self.viewers.append(viewer)

    def _tap(self, direction: str, time: float, data: bytes) -> None:
        for viewer in self.viewers:
            viewer(direction, time, data)
        if self.recorder is None:
            return
        try:
            self.recorder(direction, time, data)
        except AppmodeError as exc:
            self._drop_recorder()
            self._recording_failed(str(exc))

    def _recording_failed(self, text: str) -> None:
        """A recording stopped on its own: said as an error, and remembered for the exit
        status; the session and its stop go on."""
        self.recording_failure = text
        self.say(f"error: {text}; recording stopped")

    def _drop_recorder(self) -> None:
        """Stop recording: what it still holds is written (never waiting long)."""
        recorder, self.recorder = self.recorder, None
        if recorder is None:
            return
        try:
            recorder.close(signals.left(CLOSE_WAIT))
        except AppmodeError as exc:
            self._recording_failed(str(exc))

    def start_recording(self, path: str, origin: float | None = None) -> None:
        """Record from now on, times counted from `origin` (default: now)."""
        try:
            start = self.now() if origin is None else origin
            recorder = open_recorder(
                path,
                start,
                board_line(self.host.profile, self.target.sim_drive),
                layout=self.host.profile.a_layout,
            )
        except AppmodeError as exc:
            if self.recorder is None:
                raise
            raise AppmodeError(f"{exc}; still recording to {self.recorder.name}") from None
        self._drop_recorder()
        self.recorder = recorder
        self.say(f"recording to {path}")

    def stop_recording(self) -> None:
        if self.recorder is None:
            self.say("not recording")
            return
        self._drop_recorder()
        self.say("recording stopped")

    # ------------------------------------------------------------ commands

    def run(self, line: str) -> Step:
        """Run one command line; returns a Wait for `wait`, SHOW_STATUS for `status`,
        SHOW_HELP for `help`. Raises Quit to leave.

        Mistakes are reported as messages, never raised.
        """
        if len(line.rstrip("\r\n")) > MAX_COMMAND:  # a script's line ends with its newline
            self.fail(
                f"a command line of over {MAX_COMMAND:,} characters: a command is shorter "
                "(was a file given by mistake?)"
            )
            return None
        try:
            words = shlex.split(line, comments=True)
        except ValueError as exc:
            self.fail(str(exc))
            return None
        if not words:
            return None
        try:
            return self._command(words[0].lower(), words[1:])
        except (AppmodeError, ValueError) as exc:
            self.fail(str(exc))
            return None

    def _command(self, name: str, args: list[str]) -> Step:
        name = COMMON_ALIASES.get(name, self.aliases.get(name, name))
        spec = self._specs.get(name)
        if spec is None:
            raise AppmodeError(f"unknown command {name!r}: type help for the list")
        return spec.run(self, args)
