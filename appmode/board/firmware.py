"""The board's firmware as a deterministic state machine with an injected clock.

`Board.receive(data, now)` applies host bytes at time `now`; `Board.poll(now)` returns
the telemetry due by `now`. Time only moves forward (an earlier `now` counts as the
board's current time). The control loop runs in fixed ticks of TICK seconds from boot;
every SLOT_TICKS-th tick is a telemetry slot (§3.4). The same inputs at the same times
give the same bytes, whatever the pattern of `poll` calls.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from appmode.board.store import MemoryStore, Store
from appmode.board.vehicle import Vehicle, wrap_degrees
from appmode.errors import AppmodeError
from appmode.protocol import app, params
from appmode.protocol.directions import PAGE_LETTERS, Page, motion_for, target_velocity
from appmode.protocol.escaping import escape

TICK = 0.01
SLOT_TICKS = 5
SLOT = TICK * SLOT_TICKS
MAX_CATCH_UP = 200
"""Ticks run one by one when the board falls behind; beyond that it skips ahead."""
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
    ) -> None:
        self.store: Store = store if store is not None else MemoryStore()
        self.notes: deque[Note] = deque(maxlen=MAX_NOTES)
        saved, warning = self.store.load()
        if warning is not None:
            self._note(now, "warning", warning)
        self.params: list[int] = list(saved if saved is not None else params.DEFAULTS)
        if drive is not None:
            mode = self.params[params.SYSTEM_MODE] & ~params.DRIVE_MASK
            self.params[params.SYSTEM_MODE] = mode | int(drive)
        self.page = Page.DIRECTION
        self.direction = 0
        self.vehicle = Vehicle()
        if centivolts is not None:
            self.vehicle.centivolts = centivolts
        self.errors = 0
        self.warnings = 0
        self._boot = now
        self._tick = 0  # index of the next tick to run
        self._show_a = True
        self._c_pending = False
        self._outbox = bytearray()
        self._decoder = app.HostDecoder()

    # ------------------------------------------------------------ clock

    def next_slot(self) -> float:
        """When the next telemetry record is due."""
        ticks = -self._tick % SLOT_TICKS
        return self._boot + (self._tick + ticks) * TICK

    def advance(self, now: float) -> None:
        """Run every tick due by `now`."""
        due = int((now - self._boot) / TICK + 1e-9) + 1
        if due - self._tick > MAX_CATCH_UP:
            skipped = due - MAX_CATCH_UP - self._tick
            self.vehicle.step(self._target(), skipped * TICK)
            self._tick += skipped
        while self._tick < due:
            if self._tick:
                self.vehicle.step(self._target(), TICK)
            if self._tick % SLOT_TICKS == 0:
                self._send_slot()
            self._tick += 1

    # ------------------------------------------------------------ I/O-free edges

    def receive(self, data: bytes, now: float) -> None:
        """Apply host bytes that arrived at `now`."""
        self.advance(now)
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
        drive = params.drive_type(self.params[params.SYSTEM_MODE])
        assert drive is not None, "set frames with an invalid drive type are rejected"
        return drive

    def _mode(self, name: str) -> bool:
        return bool(self.params[params.SYSTEM_MODE] & params.MODE_BIT[name])

    def _target(self) -> tuple[float, float, float]:
        speed = float(self.params[params.MAX_SPEED])
        if self._mode("motor_reverse"):
            speed = -speed
        return target_velocity(self.page, self.direction, speed, self.drive_type.differential)

    def _send_slot(self) -> None:
        record: app.Record
        if self._c_pending:
            self._c_pending = False
            record = app.ParamsRecord(tuple(self.params))
        elif self._show_a:
            sign = -1 if self._mode("encoder_reverse") else 1
            v = self.vehicle
            record = app.Velocity(
                sign * round(v.vx), sign * round(v.vy), sign * round(v.vz), 0
            )
        else:
            v = self.vehicle
            yaw = -v.heading if self._mode("gyro_reverse") else v.heading
            record = app.Attitude(round(v.pitch), round(v.roll), wrap_degrees(yaw), v.battery)
        self._show_a = not self._show_a
        self._outbox += app.encode(record)

    def _note(self, now: float, level: str, text: str) -> None:
        self.notes.append(Note(now, level, text))

    def _apply(self, event: app.HostEvent, now: float) -> None:
        shown = escape(event.raw)
        if isinstance(event, app.Move):
            self.direction = event.direction
            motion = motion_for(self.page, event.direction)
            name = motion.name if motion else "stop"
            self._note(now, "applied", f"{shown}: {name} ({self.page.value} page)")
        elif isinstance(event, app.Stop):
            self.direction = 0
            self._note(now, "applied", f"{shown}: stop")
        elif isinstance(event, app.SwitchPage):
            self.direction = 0
            self.page = PAGE_LETTERS[event.letter]
            self._note(now, "applied", f"{shown}: stop, {self.page.value} page")
        elif isinstance(event, app.Noise):
            self.direction = 0
            self.errors += 1
            self._note(now, "rejected", f"{shown}: unrecognised byte, stop")
        elif isinstance(event, app.BadFrame):
            self.errors += 1
            self._note(now, "rejected", f"{shown}: {event.reason}")
        elif isinstance(event, app.SetParam):
            self.params[event.index] = event.value
            self._note(now, "applied", f"{shown}: {event.name} = {event.value}")
        else:
            self._apply_q(event, now, shown)

    def _apply_q(
        self, event: app.ReadParams | app.SaveParams, now: float, shown: str
    ) -> None:
        if event.warning is not None:
            self.warnings += 1
            self._note(now, "warning", f"{shown}: {event.warning}")
        if isinstance(event, app.ReadParams):
            self._c_pending = True
            self._note(now, "applied", f"{shown}: read parameters, C record in next slot")
            return
        saved = params.saved_form(self.params)
        try:
            self.store.save(saved)
        except AppmodeError as exc:
            self.errors += 1
            self._note(now, "rejected", f"{shown}: save failed: {exc}")
            return
        self._note(now, "applied", f"{shown}: saved {list(saved)}")
