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

import time
from collections.abc import Callable, Iterable, Iterator
from functools import partial

import serial

from appmode.errors import AppmodeError
from appmode.host.link import Link
from appmode.host.query import AGREE, TRIES
from appmode.host.state import LinkStatus
from appmode.line.wire import UART2_BAUD, Tap
from appmode.ports.link import is_simulated, open_link
from appmode.ports.sim import sim_side
from appmode.protocol import control, params, reader, settings
from appmode.protocol.params import DriveType

READ_TIMEOUT = 0.1
"""Seconds to wait for a reply: the board answers in its next 10 ms tick (§11)."""
ROTATE_TIMEOUT = 20.0
ROTATE_POLL = 0.1
"""Seconds between reads of the pending angle while a rotation goes on."""

Event = control.BoardEvent | LinkStatus
OPEN_UART2 = partial(open_link, baud=UART2_BAUD)


def uart2_url(url: str) -> str:
    """The control port of `url`: a sim:// URL without `port=` opens the simulated
    board's UART2; a device opens at 115200 bps unless it says `?baud=`."""
    if is_simulated(url) and "port=" not in url.lower():
        return url + ("&" if "?" in url else "?") + "port=uart2"
    return url


class ControlHost(Link[control.BoardEvent]):
    """A session with one board's control port."""

    sent = "2>"
    received = "2<"

    def __init__(
        self,
        url: str,
        tap: Tap | None = None,
        clock: Callable[[], float] = time.monotonic,
        opener: Callable[[str], serial.SerialBase] = OPEN_UART2,
        stop_on_close: bool = True,
        drive: DriveType | None = None,
        timeout: float = READ_TIMEOUT,
        tries: int = TRIES,
    ) -> None:
        url = uart2_url(url)
        if is_simulated(url) and sim_side(url) != "uart2":
            raise AppmodeError(
                f"{url} is the simulated board's APP port: --uart2 speaks the control "
                "port's frames; use port=uart2 or leave port= out"
            )
        super().__init__(url, tap, clock, opener)
        self.stop_on_close = stop_on_close
        self.timeout = timeout
        self.tries = tries
        self._drive = drive
        self._decoder = control.BoardDecoder(None)
        self._sent = control.HostDecoder(drive or DriveType.OMNI)
        """What was sent, decoded as the board does: is a frame left open?"""
        self._held: list[Event] = []
        self.watch: Callable[[str, reader.Event | LinkStatus], None] | None = None
        """Called with each frame sent (`2>`) and each event received (`2<`) as it is
        decoded: a session printing as it goes."""

    # ------------------------------------------------------------ bytes

    def _on_lost(self) -> None:
        self._decoder = control.BoardDecoder(None, self._decoder.app_mode)

    def send(self, data: bytes) -> None:
        """Write bytes to the control port; LinkLost if the link is down."""
        self._write(data)
        for event in self._sent.feed(data):
            self._follow(event)
            if self.watch is not None:
                self.watch(self.sent, event)

    def send_frame(self, *frames: control.HostFrame) -> bytes:
        """Encode and send frames, after zeros completing a frame that raw bytes left
        open, so that the board reads them whole; the bytes sent. AppmodeError names a
        value out of range."""
        try:
            data = self._sent.rest() + b"".join(control.encode(f) for f in frames)
        except ValueError as exc:
            raise AppmodeError(f"{type(frames[0]).__name__}: {exc}") from None
        self.send(data)
        return data

    def _follow(self, event: object) -> None:
        """Track a system_mode this host set: the drive type fixes frame lengths and
        the encoding of velocity, bit 7 moves the APP protocol onto this port (§12)."""
        mode = control.system_mode_set(event)
        if mode is None:
            return
        drive = params.drive_type(mode)
        if drive is not None:
            self._drive = drive
            self._sent.drive = drive
        on = bool(mode & params.MODE_BIT["app_mode"])
        self._held += self._decoder.set_app_mode(on)
        self._sent.set_app_mode(on)

    def _read_once(self, block: bool) -> list[Event]:
        events, self._held = self._held, []
        return events + self._receive(block and not events)

    def _receive(self, block: bool) -> list[Event]:
        events: list[Event] = list(self._take_pending())
        data = self._read_bytes(block)
        events += self._take_pending()
        if data:
            events += self._decoder.feed(data)
        if self.watch is not None:
            for event in events:
                self.watch(self.received, event)
        return events

    def _wait(self, done: Callable[[Event], bool], timeout: float) -> None:
        """Read until an event satisfies `done` or `timeout` passes; every event read is
        kept for the next poll."""

        def read(block: bool) -> list[Event]:
            events = self._receive(block)
            self._held += events
            return events

        self._read_until(timeout, read, lambda events: any(done(e) for e in events))

    # ------------------------------------------------------------ reads

    def read_values(self, names: Iterable[str]) -> dict[str, int]:
        """Read values by name (settings, `pending_angle`, `speed_a`…, `position_a`…).
        Each read is sent AGREE times at once, so the board answers every copy in the
        same tick, from the same state: a value is reported when its replies agree. A
        round without that is sent again; AppmodeError after `tries` rounds."""
        reads = list(dict.fromkeys(settings.read_named(name) for name in names))
        agreed: dict[str, int] = {}
        heard = False
        for _ in range(self.tries):
            want = [r for r in reads if r.name not in agreed]
            if not want:
                break
            replies: dict[int, list[int]] = {r.reply_id: [] for r in want}

            def done(event: Event, replies: dict[int, list[int]] = replies) -> bool:
                if isinstance(event, control.Reply) and event.id in replies:
                    replies[event.id].append(event.value)
                return all(len(v) >= AGREE for v in replies.values())

            self.send_frame(*(control.ReadFrame(r) for r in want for _ in range(AGREE)))
            self._wait(done, self.timeout)
            for r in want:
                values = replies[r.reply_id]
                heard = heard or bool(values)
                if len(values) >= AGREE and len(set(values)) == 1:
                    agreed[r.name] = values[0]
        missing = [r.name for r in reads if r.name not in agreed]
        if missing:
            what = "no two replies agreed" if heard else "no reply"
            raise AppmodeError(
                f"{what} reading {', '.join(missing)} on {self.url} after {self.tries} "
                "tries: is this the board's control port (UART2, 115200 bps)? The "
                "reference firmware does not answer reads (docs/protocol.md §13)"
            )
        return {r.name: agreed[r.name] for r in reads}

    def read(self, name: str) -> int:
        return self.read_values([name])[settings.read_named(name).name]

    def settings(self) -> dict[str, int]:
        """The ten settings, by name."""
        return self.read_values(s.name for s in settings.SETTINGS)

    @property
    def drive(self) -> DriveType:
        """The board's drive type (read from system_mode the first time it is needed)."""
        if self._drive is None:
            mode = self.read("system_mode")
            drive = params.drive_type(mode)
            if drive is None:
                raise AppmodeError(
                    f"the board's system_mode is {mode}: its drive type (bits 0–2) is not "
                    "one of 0–3; set it with --set system_mode=N"
                )
            self._drive = drive
            self._sent.drive = drive
        return self._drive

    @property
    def known_drive(self) -> DriveType | None:
        """The drive type if known, without asking the board."""
        return self._drive

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
        setting = settings.lookup(name)
        error = settings.value_error(setting, value)
        if error is not None:
            raise AppmodeError(error)
        got = None
        for _ in range(self.tries):
            self.send_frame(control.SetSetting(setting, value))
            got = self.read(setting.name)
            if got == value:
                return got
        raise AppmodeError(
            f"{setting.name} still reads {got} on {self.url} after {self.tries} sets of "
            f"{value}: the board does not take it"
        )

    def store(self, op: str) -> None:
        """`load`, `defaults` or `save` (§10). No reply comes: a save is confirmed only
        by reading the settings after the board restarts."""
        self.send_frame(control.store(op))
        if op != "save":
            self._drive = None  # system_mode may have changed: read it when needed

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
                f"motors: a {self.drive.cli_name} car has {self.wheels()} motors, "
                f"not {len(speeds)}"
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
        deadline = self.now() + timeout
        while True:
            self._wait(lambda event: False, ROTATE_POLL)
            left = self.read("pending_angle")
            if left == 0:
                return
            if self.now() > deadline:
                raise AppmodeError(
                    f"rotate: {left / 10:g}° still to turn after {timeout:g} s (is the car "
                    "held, or max_speed 0?)"
                )

    def reports(self, duration: float | None = None) -> Iterator[control.EncoderReport]:
        """Encoder reports as they arrive (turn them on with set_mode_bit)."""
        for event in self.events(duration):
            if isinstance(event, control.EncoderReport):
                yield event

    # ------------------------------------------------------------ end

    @property
    def stop_bytes(self) -> bytes:
        """What closing sends: the zero velocity frame, after zeros completing a frame
        left open by raw bytes; in APP mode (§12) `Z`, after `{}` closing an open frame."""
        if self._sent.app_mode:
            return b"{}Z" if self._sent.buffered else b"Z"
        return self._sent.rest() + control.STOP

    def _stop(self) -> bytes:
        return self.stop_bytes

