"""The host over a board's control port (UART2, docs/protocol.md Part II): drive with
velocity, motor and position frames, read, set (verified), load and save the ten
settings, read the encoders and the pending angle, follow the encoder report.

The line has no checksum, so a read is reported only when AGREE replies agree (as the
APP host does with C records); a request unanswered within its timeout is sent again, a
bounded number of times. Any 10 bytes sent here make the
control port take over the motion from the APP port (§8.3). Closing, for any reason,
sends a zero velocity frame last (after completing a frame left open by raw bytes).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable, Iterator
from functools import partial

from appmode.board.profiles import SHEET, Profile
from appmode.errors import AppmodeError
from appmode.host.control.query import (
    ROTATE_POLL,
    ROTATE_TIMEOUT,
    ControlOutcome,
    ReadDone,
    ReadQuery,
    rotation_done,
)
from appmode.host.control.state import ControlState, PortMode
from appmode.host.events import LinkStatus
from appmode.host.link import Link, LinkLost, Opener
from appmode.host.outcomes import TRIES, QueryFailed
from appmode.line.wire import UART2_BAUD, Tap
from appmode.ports.target import AnyTarget, as_target
from appmode.ports.urls import open_link
from appmode.protocol import app, control, params, reader, settings
from appmode.protocol.control_view import describe
from appmode.protocol.directions import PAGE_LETTERS, letter_name
from appmode.protocol.params import DriveType

READ_TIMEOUT = 0.1
"""Seconds to wait for a reply: the board answers in its next 10 ms tick (§11)."""

Event = control.BoardEvent | ControlOutcome | PortMode | LinkStatus
OPEN_UART2 = partial(open_link, baud=UART2_BAUD)


class ControlHost(Link[control.BoardEvent | ControlOutcome | PortMode]):
    """A session with one board's control port."""

    sent = "2>"
    received = "2<"

    def __init__(
        self,
        url: AnyTarget,
        tap: Tap | None = None,
        opener: Opener = OPEN_UART2,
        stop_on_close: bool = True,
        profile: Profile = SHEET,
        drive: DriveType | None = None,
        timeout: float = READ_TIMEOUT,
        tries: int = TRIES,
    ) -> None:
        """`profile`: the board's firmware (the byte UART2 takes over at, its drive type
        if fixed); `drive`: the car's drive type if known (else read when needed)."""
        target = as_target(url).for_uart2()  # a device opens at 115200 unless ?baud=
        if target.simulated and target.sim_port != "uart2":
            raise AppmodeError(
                f"{target} is the simulated board's APP port: --uart2 speaks the control "
                "port's frames; use port=uart2 or leave port= out"
            )
        super().__init__(target, tap, opener)
        self.stop_on_close = stop_on_close
        self.timeout = timeout
        self.tries = tries
        self.profile = profile
        self.state = ControlState(drive or profile.fixed_drive, profile.takeover_byte)
        self._held: list[Event] = []
        self._put_back: control.SetSetting | None = None
        self.watch: Callable[[str, reader.Event | LinkStatus | PortMode], None] | None = None
        """Called with each frame sent (`2>`) and each event received (`2<`) as it is
        decoded: a session printing as it goes."""

    # ------------------------------------------------------------ bytes

    def _on_lost(self) -> None:
        self.state.reset_decoder()

    def _sent(self, data: bytes) -> None:
        events, reread = self.state.sent(data, self.now())
        self._watch(self.sent, events)
        self._watch(self.received, reread)
        self._held += reread

    def send_frame(self, *frames: control.HostFrame) -> bytes:
        """Encode and send frames, after zeros completing a frame that raw bytes left
        open, so that the board reads them whole; the bytes sent. AppmodeError names a
        value out of range."""
        try:
            data = b"".join(control.encode(f) for f in frames)
        except ValueError as exc:
            raise AppmodeError(f"{type(frames[0]).__name__}: {exc}") from None
        return self._send_whole(data)

    def _send_whole(self, data: bytes) -> bytes:
        data = self.state.sent_decoder.rest() + data
        self.send(data)
        return data

    def _read_once(self, block: bool) -> list[Event]:
        held, self._held = self._held, []
        new = self._take_pending()
        data = self._read_bytes(block and not (held or new))
        new += self._take_pending()
        if data:
            new += self.state.feed(data, self.now())
        outcome = self.state.tick(self.now())
        if outcome is not None:
            new.append(outcome)
        self._flush_outbox()
        self._watch(self.received, new)
        return held + new

    def _watch(self, direction: str, events: Iterable[object]) -> None:
        if self.watch is not None:
            for event in events:
                if not isinstance(event, (ReadDone, QueryFailed)):
                    self.watch(direction, event)  # type: ignore[arg-type]

    def _flush_outbox(self) -> None:
        data = self.state.take_outbox()
        if data:
            with contextlib.suppress(LinkLost):  # the query times out and tries again
                self._send_whole(data)

    # ------------------------------------------------------------ reads

    def start_query(self, query: ReadQuery) -> None:
        """Begin a read or set without waiting; its outcome comes with the events."""
        self.state.start_query(query, self.now())
        self._flush_outbox()

    def query(self, query: ReadQuery) -> dict[str, int]:
        """Run a read or set to its end; AppmodeError if it fails. Other events read
        meanwhile are kept for the next poll."""
        self.start_query(query)
        kept: list[Event] = []
        try:
            while True:
                for event in self.poll(query.timeout):
                    if isinstance(event, ReadDone):
                        return event.values
                    if isinstance(event, QueryFailed):
                        raise AppmodeError(event.text)
                    kept.append(event)
        finally:
            self._held = kept + self._held

    def read_values(self, names: Iterable[str]) -> dict[str, int]:
        """Read values by name (settings, `pending_angle`, `speed_a`…, `position_a`…),
        each reported only when its replies agree (control_query); AppmodeError after
        `tries` rounds."""
        return self.query(self.new_query(names, None))

    def read(self, name: str) -> int:
        return self.read_values([name])[settings.read_named(name).name]

    def settings(self) -> dict[str, int]:
        """The ten settings, by name."""
        return self.read_values(s.name for s in settings.SETTINGS)

    @property
    def drive(self) -> DriveType:
        """The board's drive type (read from system_mode the first time it is needed)."""
        if self.state.drive is None:
            mode = self.read("system_mode")
            if self.state.drive is None:
                raise AppmodeError(
                    f"the board's system_mode is {mode}: its drive type (bits 0–2) is not "
                    "one of 0–3; set it with --set system_mode=N"
                )
        return self.state.drive

    @property
    def telemetry(self) -> None:
        """No APP records come here (APP mode's are the APP port's own, §12)."""
        return None

    def in_force_text(self) -> str | None:
        """What the car was last told to do on this port, in words (None: stop)."""
        state = self.state
        if state.in_force is not None:
            return describe(state.in_force)
        if state.letter is None:
            return None
        page = PAGE_LETTERS[state.app_end.page_letter]
        return f"{state.letter} {letter_name(page, state.letter)} (APP letter)"

    @property
    def known_drive(self) -> DriveType | None:
        """The drive type if known, without asking the board."""
        return self.state.drive

    def wheels(self) -> int:
        return control.motor_count(self.drive)

    def encoders(self) -> dict[str, int]:
        """Each wheel's speed and position (`speed_a`…, `position_a`…)."""
        letters = settings.WHEELS[: self.wheels()]
        names = [f"{kind}_{w}" for kind in ("speed", "position") for w in letters]
        return self.read_values(names)

    def pending_angle(self) -> float:
        """The rotation angle mode still has to turn, in degrees."""
        return self.read("pending_angle") / 10

    # ------------------------------------------------------------ settings

    def set(self, name: str, value: int) -> int:
        """Set a setting and verify it by reading back (the set is sent again while the
        board shows another value); returns the value read."""
        query = self.new_query((), (name, value))
        return self.query(query)[query.names[0]]

    def new_query(self, names: Iterable[str], change: tuple[str, int] | None) -> ReadQuery:
        """A read or set with this host's timeout and tries; AppmodeError for an
        unknown name or a value out of range."""
        try:
            return ReadQuery(names, change, self.timeout, self.tries, self.url)
        except ValueError as exc:
            raise AppmodeError(str(exc)) from None

    def store(self, op: str) -> None:
        """`load`, `defaults` or `save` (§10). No reply comes: a save is confirmed only
        by reading the settings after the board restarts."""
        self.send_frame(control.store(op))
        if op != "save":
            self.state.forget_drive()  # system_mode may have changed: read it when needed

    def set_in_app_mode(self, name: str, value: int) -> None:
        """Set system_mode while the port speaks APP text (§12): the APP frame `{8:…}`,
        which a board in APP mode reads; AppmodeError for any other setting."""
        if name != "system_mode":
            raise AppmodeError(
                "UART2 is in APP mode (system_mode bit 7): it takes APP letters and frames, "
                "not settings frames; set system_mode without bit 7 first"
            )
        error = settings.value_error(settings.lookup(name), value)
        if error is not None:
            raise AppmodeError(error)
        self.send(app.encode(app.SetParam(params.SYSTEM_MODE, value)))

    def set_mode_bit(self, name: str, on: bool) -> int:
        """Turn a system_mode bit (`encoder_report`, `app_mode`…) on or off, verified."""
        mode = self.read("system_mode")
        bit = params.MODE_BIT[name]
        return self.set("system_mode", mode | bit if on else mode & ~bit)

    # ------------------------------------------------------------ motion

    def velocity(self, x: int = 0, y: int = 0, z: int = 0, **kwargs: int) -> bytes:
        """A velocity frame for the board's drive type (control.velocity: x, y, z; diff:
        y and z as duties; diff-gyro: left=, right=; angle= in 0.1°)."""
        try:
            frame = control.velocity(self.drive, x, y, z, **kwargs)
        except ValueError as exc:
            raise AppmodeError(f"velocity: {exc}") from None
        return self.send_frame(frame)

    def stop(self) -> bytes:
        """Stop the car now (stop_bytes); the bytes sent."""
        stop = self.stop_bytes
        self.send(stop)
        return stop

    def motors(self, speeds: tuple[int, ...]) -> bytes:
        if len(speeds) != self.wheels():
            raise AppmodeError(
                f"motors: a {self.drive.cli_name} car has {self.wheels()} motors, not {len(speeds)}"
            )
        return self.send_frame(control.MotorFrame(speeds))

    def position(self, x: int, y: int, z: int) -> bytes:
        return self.send_frame(control.PositionFrame(x, y, z))

    def rotate(self, degrees: float, timeout: float = ROTATE_TIMEOUT) -> float:
        """Turn by `degrees` in angle mode (§9.1) and wait until the pending angle is 0;
        returns the seconds it took. AppmodeError after `timeout`."""
        start = self.now()
        self.start_rotation(degrees)
        self.wait_rotation(timeout)
        return self.now() - start

    def start_rotation(self, degrees: float) -> bytes:
        """Send the angle-mode frame that turns by `degrees`; the bytes sent."""
        return self.velocity(angle=round(degrees * 10))

    def wait_rotation(self, timeout: float = ROTATE_TIMEOUT) -> None:
        """Wait until the pending angle reads 0; AppmodeError after `timeout`."""
        start = self.now()
        while True:
            self._held = [*self.events(ROTATE_POLL), *self._held]  # kept for the next poll
            if rotation_done(self.read("pending_angle"), self.now() - start, timeout):
                return

    def reports(self, duration: float | None = None) -> Iterator[control.EncoderReport]:
        """Encoder reports as they arrive (turn them on with set_mode_bit)."""
        for event in self.events(duration):
            if isinstance(event, control.EncoderReport):
                yield event

    # ------------------------------------------------------------ end

    @property
    def stop_bytes(self) -> bytes:
        """What stops the car whatever mode the port is in: zeros completing a frame left
        open by raw bytes, then the zero velocity frame (in APP mode its last byte stops
        the car too, §2.1); while APP mode may be on (§12), then `Z` (after `{}` closing
        an APP frame left open)."""
        return self._stop_with(control.STOP)

    def put_back_on_close(self, name: str, value: int) -> None:
        """Set `name` back to `value` when the session closes, just before its stop
        (a setting changed for the session only: the encoder report)."""
        self._put_back = control.setting(name, value)

    def _stop(self) -> bytes:
        if self._put_back is None or self.state.app_mode:
            return self.stop_bytes
        return self._stop_with(control.encode(self._put_back) + control.STOP)

    def _stop_with(self, frames: bytes) -> bytes:
        sent = self.state.sent_decoder
        if not self.state.app_maybe:
            return sent.rest() + frames
        close = b"{}" if sent.app_mode and sent.buffered else b""
        return sent.rest() + close + frames + app.encode(app.Stop())
