"""The board's firmware as a deterministic state machine with an injected clock.

`Board.receive(data, now)` applies host bytes at time `now`; `Board.poll(now)` returns
the telemetry due by `now`. Time only moves forward (an earlier `now` counts as the
board's current time). The control loop runs in fixed ticks of TICK seconds from boot;
records go out on the profile's schedule (§3.4, §13), on a millisecond grid. The same
inputs at the same times give the same bytes, whatever the pattern of `poll` calls.
Every way a profile differs is a switch of `profiles.Profile`.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from appmode.board.intake import INT_PARAMS, FirmwareIntake, Frame, c_int
from appmode.board.profiles import SHEET, Profile
from appmode.board.store import MemoryStore, Store
from appmode.board.vehicle import Vehicle, battery_percent, wrap_degrees
from appmode.errors import AppmodeError
from appmode.protocol import app, params
from appmode.protocol.directions import PAGE_LETTERS, Page, motion_for, target_velocity
from appmode.protocol.escaping import escape

TICK = 0.01
TICK_MS = 10
SLOT = 0.05
"""The sheet profile's time between records."""
APP_BYTE = 10 / 9600
"""A byte's time on the APP port's wire."""
MAX_CATCH_UP = 200
"""Ticks run one by one when the board falls behind; beyond that it skips ahead."""
MAX_RAMP = 2000
"""Ticks of a ramp run when the board skips ahead (20 s: any ramp has settled)."""
MAX_NOTES = 1000
"""Log lines kept until taken: an edge that never reads them costs bounded memory."""


@dataclass(frozen=True, slots=True)
class Note:
    """One line of the board's own log: what it received and what it did with it."""

    time: float
    level: str  # "applied", "rejected", "warning" or "info"
    text: str


class Board:
    """The firmware: pages, directions, parameters, telemetry schedule, flash."""

    def __init__(
        self,
        store: Store | None = None,
        *,
        drive: params.DriveType | None = None,
        now: float = 0.0,
        centivolts: float | None = None,
        profile: Profile = SHEET,
    ) -> None:
        self.profile = profile
        self.store: Store = store if store is not None else MemoryStore()
        self.notes: deque[Note] = deque(maxlen=MAX_NOTES)
        saved = None
        if profile.saves:
            saved, warning = self.store.load()
            if warning is not None:
                self._note(now, "warning", warning)
        self.params: list[float] = list(saved if saved is not None else profile.defaults)
        profile.check(drive=drive is not None, flash=False)
        if drive is not None:
            mode = int(self.params[params.SYSTEM_MODE]) & ~params.DRIVE_MASK
            self.params[params.SYSTEM_MODE] = mode | int(drive)
        self.page = Page.DIRECTION
        self.direction = 0
        self.turn = 0  # a rotation held apart from the direction (sticky_rotation)
        self.vehicle = Vehicle()
        if centivolts is not None:
            self.vehicle.centivolts = centivolts
        self.errors = 0
        self.warnings = 0
        self._boot = now
        self._tick_ms = 0  # the next control tick, in ms from boot
        self._record_ms = 0  # the next record
        self._show_a = profile.first_record == "A"
        self._startup = profile.startup_text
        self._c_pending = False
        self._c_on_wire_until = -math.inf
        self._outbox = bytearray()
        self._decoder = app.HostDecoder()
        self._intake = FirmwareIntake(profile.steer_in_frames, profile.frame_restarts)

    # ------------------------------------------------------------ clock

    def next_slot(self) -> float:
        """When the next record is due."""
        return self._boot + self._record_ms / 1000

    def advance(self, now: float) -> None:
        """Run every tick and record due by `now`."""
        due = math.floor((now - self._boot) * 1000 + 1e-6)
        behind = (due - self._tick_ms) // TICK_MS
        if behind > MAX_CATCH_UP:
            skipped = behind - MAX_CATCH_UP
            self._control(skipped)
            self._tick_ms += skipped * TICK_MS
            if self._record_ms < self._tick_ms:
                period = self.profile.period_ms or TICK_MS
                late = self._tick_ms - self._record_ms
                self._record_ms += -(-late // period) * period
        while min(self._tick_ms, self._record_ms) <= due:
            if self._tick_ms <= self._record_ms:
                if self._tick_ms:
                    self._control(1)
                self._tick_ms += TICK_MS
            else:
                self._send_record()

    # ------------------------------------------------------------ I/O-free edges

    def receive(self, data: bytes, now: float) -> None:
        """Apply host bytes that arrived at `now`."""
        self.advance(now)
        if self.profile.firmware_frames:
            for item in self._intake.feed(data):
                if isinstance(item, Frame):
                    self._apply_frame(item, now)
                else:
                    self._apply(item.event, now, framed=item.framed)
        else:
            for event in self._decoder.feed(data):
                self._apply(event, now)

    def poll(self, now: float) -> bytes:
        """The telemetry bytes due by `now`."""
        self.advance(now)
        out = bytes(self._outbox)
        self._outbox.clear()
        return out

    def take_notes(self) -> list[Note]:
        notes = list(self.notes)
        self.notes.clear()
        return notes

    # ------------------------------------------------------------ firmware

    @property
    def drive_type(self) -> params.DriveType:
        if not self.profile.drive_types:
            return params.DriveType.OMNI
        drive = params.drive_type(int(self.params[params.SYSTEM_MODE]))
        assert drive is not None, "set frames with an invalid drive type are rejected"
        return drive

    def _powered(self, ms: int) -> bool:
        """Whether the motors run at `ms` after power-up (not in the profile's dead time,
        when the battery voltage also reads 0)."""
        return ms >= self.profile.dead_time * 1000

    def _mode(self, name: str) -> bool:
        return bool(int(self.params[params.SYSTEM_MODE]) & params.MODE_BIT[name])

    def _control(self, ticks: int) -> None:
        """`ticks` control ticks of TICK seconds."""
        profile = self.profile
        speed = self.params[params.MAX_SPEED]
        if 0 < speed < profile.stall_speed:
            self.params[params.MAX_SPEED] = speed = profile.stall_speed
        if profile.ramp is None:
            self.vehicle.step(self._target(speed), ticks * TICK)
            return
        pushes = self._pushes() if self._powered(self._tick_ms) else (0, 0, 0)
        for _ in range(min(ticks, MAX_RAMP)):  # beyond that a ramp has long settled
            self.vehicle.ramp(pushes, speed, profile.ramp, profile.coast, TICK)

    def _target(self, speed: float) -> tuple[float, float, float]:
        if self._mode("motor_reverse"):
            speed = -speed
        return target_velocity(
            self.page, self.direction, speed, self.drive_type.differential, self.profile.buttons
        )

    def _pushes(self) -> tuple[int | None, ...]:
        """Which way a ramping board pushes x, y, z this tick (vehicle.ramp)."""
        motion = motion_for(self.page, self.direction, self.profile.buttons)
        z: int | None = self.turn or None
        if motion is None:
            return (None, None, z)
        x, y, turn = (int(math.copysign(1, f)) if f else 0 for f in motion.holonomic)
        return (x, y, turn or z)

    def _send_record(self) -> None:
        profile = self.profile
        at = self._record_ms
        data = self._startup
        if data:
            self._startup = b""
        elif self._c_pending:
            self._c_pending = False
            values = tuple(c_int(v) if profile.c_saturates else int(v) for v in self.params)
            data = app.encode(app.ParamsRecord(values))
            self._c_on_wire_until = self._boot + at / 1000 + len(data) * APP_BYTE
            self._show_a = not self._show_a
        else:
            data = app.encode(self._a_record(at) if self._show_a else self._b_record(at))
            self._show_a = not self._show_a
        self._outbox += data
        if profile.period_ms is not None:
            self._record_ms = at + profile.period_ms
        else:
            wire = len(data) * profile.byte_ms
            step = profile.pause_step_ms
            self._record_ms = at + step * math.ceil(wire / step - 1e-9) + profile.pause_ms

    def _whole(self, value: float) -> int:
        return math.trunc(value) if self.profile.truncate else round(value)

    def _battery(self, ms: int) -> int:
        volts = self.vehicle.centivolts if self._powered(ms) else 0.0
        return battery_percent(volts, self.profile.battery_floor)

    def _a_record(self, ms: int) -> app.Velocity:
        layout = self.profile.a_layout
        v = self.vehicle
        sign = -1 if self._mode("encoder_reverse") else 1
        fields = [0, 0, 0, 0]
        for i, value in zip(layout.motion, (v.vx, v.vy, v.vz), strict=False):
            shown = self._whole(sign * value * layout.scale)
            fields[i] = shown if layout.signed else abs(shown) % 256
        if layout.battery is not None:
            fields[layout.battery] = self._battery(ms)
        return app.Velocity(fields[0], fields[1], fields[2], fields[3])

    def _b_record(self, ms: int) -> app.Attitude:
        profile, v = self.profile, self.vehicle
        yaw = -v.heading if self._mode("gyro_reverse") else v.heading
        return app.Attitude(
            self._whole(v.pitch),
            self._whole(v.roll),
            wrap_degrees(yaw, profile.yaw_low, profile.truncate),
            self._battery(ms),
        )

    def _note(self, now: float, level: str, text: str) -> None:
        self.notes.append(Note(now, level, text))

    def _steer(self, event: app.ByteEvent) -> str:
        """Apply one byte's direction logic (§2.1, §4; §13's rotation rule); what it did."""
        sticky = self.profile.sticky_rotation
        if isinstance(event, app.SwitchPage):
            self.page = PAGE_LETTERS[event.letter]
            self.direction = 0
            if self.page is Page.BUTTON:
                self.turn = 0
            return f"stop, {self.page.value} page"
        if isinstance(event, app.Move) and (
            self.page is Page.DIRECTION or not event.numeric or self.profile.numeric_buttons
        ):
            motion = motion_for(self.page, event.direction, self.profile.buttons)
            if motion is None:
                self.direction = 0
                self.turn = 0
                return f"stop ({event.letter} is no button here)"
            x, y, z = motion.holonomic
            if sticky and self.page is Page.BUTTON and z and not (x or y):
                self.direction, self.turn = 0, int(math.copysign(1, z))
            else:
                self.direction, self.turn = event.direction, 0
            return f"{motion.name} ({self.page.value} page)"
        self.direction = 0
        if self.page is Page.BUTTON or not sticky:
            self.turn = 0
        return "stop" if not self.turn else "stop; the rotation goes on (§13)"

    def _apply(self, event: app.HostEvent, now: float, framed: bool = False) -> None:
        shown = escape(event.raw)
        if isinstance(event, (app.Move, app.Stop, app.SwitchPage, app.Noise)):
            before = (self.direction, self.turn, self.page)
            did = self._steer(event)
            if isinstance(event, app.Noise):
                self.errors += not framed
                did = f"unrecognised byte, {did}"
            if not framed:
                self._note(
                    now,
                    "rejected" if isinstance(event, app.Noise) else "applied",
                    f"{shown}: {did}",
                )
            elif before != (self.direction, self.turn, self.page):
                self._note(now, "applied", f"{shown} in a frame: {did} (§13)")
        elif isinstance(event, app.BadFrame):
            self.errors += 1
            self._note(now, "rejected", f"{shown}: {event.reason}")
        elif isinstance(event, app.SetParam):
            self.params[event.index] = event.value
            self._note(now, "applied", f"{shown}: {event.name} = {event.value}")
        else:
            if event.warning is not None:
                self.warnings += 1
                self._note(now, "warning", f"{shown}: {event.warning}")
            (self._read if isinstance(event, app.ReadParams) else self._save)(now, shown)

    def _apply_frame(self, frame: Frame, now: float) -> None:
        shown = escape(frame.raw)
        if frame.action == "read":
            self._read(now, shown)
        elif frame.action == "save":
            self._save(now, shown)
        elif frame.action == "ignored" or frame.index not in self.profile.settable:
            reason = frame.reason or f"parameter {frame.index} is not settable on this board"
            self._note(now, "rejected", f"{shown}: ignored: {reason}")
        else:
            index = frame.index
            kept = c_int(frame.value) if index in INT_PARAMS else frame.value
            self.params[index] = kept
            name = params.PARAMS[index].name
            self._note(now, "applied", f"{shown}: {name} = {kept:.10g}")

    def _read(self, now: float, shown: str) -> None:
        if self.profile.read_lost_in_c and now < self._c_on_wire_until:
            self._note(now, "rejected", f"{shown}: lost: a C record is going out (§13)")
            return
        self._c_pending = True
        self._note(now, "applied", f"{shown}: read parameters, C record in next slot")

    def _save(self, now: float, shown: str) -> None:
        if not self.profile.saves:
            self._note(now, "rejected", f"{shown}: this board saves nothing (§13)")
            return
        saved = params.saved_form([int(v) for v in self.params])
        try:
            self.store.save(saved)
        except AppmodeError as exc:
            self.errors += 1
            self._note(now, "rejected", f"{shown}: save failed: {exc}")
            return
        self._note(now, "applied", f"{shown}: saved {list(saved)}")
