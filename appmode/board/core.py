"""What every part of the firmware shares: the parameters, the car, the motion state, the
two ports' outgoing bytes, the log, the flash — and the few rules they all apply.

The parts (`telemetry`, `app_port`, `control_port`, and the control loop in `firmware`)
hold one `Core` each and no state of each other's.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from appmode.board.profiles import Profile
from appmode.board.store import Store
from appmode.board.vehicle import Vehicle
from appmode.errors import AppmodeError
from appmode.protocol import control, params, settings
from appmode.protocol.directions import Page

MAX_NOTES = 1000
"""Log lines kept until taken: an edge that never reads them costs bounded memory."""
UART3, UART2 = "uart3", "uart2"
"""The ports, as the board's log names them."""
DATA_SPEED = 100.0
"""The speed a data profile's board drives at, in its records' units (it has no model of
the car: its parameters mean nothing to it)."""


@dataclass(frozen=True, slots=True)
class Note:
    """One line of the board's own log: what it received and what it did with it."""

    time: float
    level: str  # "applied", "rejected", "warning" or "info"
    text: str
    port: str = UART3


class Core:
    """The firmware's shared state."""

    def __init__(
        self, profile: Profile, store: Store, drive: params.DriveType | None, now: float
    ) -> None:
        self.profile = profile
        self.store = store
        self.notes: deque[Note] = deque(maxlen=MAX_NOTES)
        saved = None
        if profile.saves:
            saved, warning = store.load()
            if warning is not None:
                self.note(now, "warning", warning)
        values = saved if saved is not None else profile.defaults
        self.params: list[float] = list(values[: params.PARAM_COUNT])
        self.gyro_calibration = (
            values[params.PARAM_COUNT] if len(values) > params.PARAM_COUNT else 0
        )
        profile.check(drive=drive is not None, flash=False)
        if drive is not None:
            mode = int(self.params[params.SYSTEM_MODE]) & ~params.DRIVE_MASK
            self.params[params.SYSTEM_MODE] = mode | int(drive)
        self.boot = now
        self.tick_ms = 0
        """The next control tick, in ms from boot."""
        self.vehicle = Vehicle(yaw_gain=math.degrees(profile.velocity_si[1]))
        self.page = Page.DIRECTION
        self.direction = 0
        self.turn = 0
        """A rotation held apart from the direction (sticky_rotation)."""
        self.errors = 0
        self.warnings = 0
        self.speed_change = 0
        """What a data profile's speed keys (`X`, `Y` on some firmware) added to its speed."""
        # the control port (§8–§12)
        self.uart2_control = False
        """UART2 has taken over the motion (§8.3)."""
        self.uart2_errors = 0
        self.pending_angle = 0.0
        """Angle mode's rotation still to turn, in 0.1°, signed (§9.1)."""
        self.command: control.HostFrame | None = None
        """The last motion frame UART2 sent that the board obeys."""
        self.position_goal: tuple[float, float, float] | None = None
        self.target_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self.reads: list[settings.Read] = []
        """UART2 reads answered at the next control tick (§11)."""
        self.out3 = bytearray()
        """Bytes due out on UART3 (the APP port)."""
        self.out2 = bytearray()
        """Bytes due out on UART2."""

    def note(self, now: float, level: str, text: str, port: str = UART3) -> None:
        self.notes.append(Note(now, level, text, port))

    @property
    def system_mode(self) -> int:
        """system_mode's bits (0 on a data profile's board: its parameters are only
        stored)."""
        if self.profile.file is not None:
            return 0
        return int(self.params[params.SYSTEM_MODE])

    @property
    def max_speed(self) -> float:
        """The speed a direction drives at: max_speed, or a data profile's DATA_SPEED and
        what its speed keys changed."""
        if self.profile.file is not None:
            return max(0.0, DATA_SPEED + self.speed_change)
        return self.params[params.MAX_SPEED]

    def mode(self, name: str) -> bool:
        """Whether a bit of system_mode is set."""
        return bool(self.system_mode & params.MODE_BIT[name])

    @property
    def drive_type(self) -> params.DriveType:
        if not self.profile.drive_types:
            return params.DriveType.OMNI
        drive = params.drive_type(self.system_mode)
        assert drive is not None, "set frames with an invalid drive type are rejected"
        return drive

    def powered(self, ms: int) -> bool:
        """Whether the motors run at `ms` after power-up (not in the profile's dead time,
        when the battery voltage also reads 0)."""
        return ms >= self.profile.dead_time * 1000

    def save(self, now: float, shown: str, port: str) -> None:
        """Write the parameters (and the gyro calibration) to flash, from either port."""
        if not self.profile.saves:
            self.note(now, "rejected", f"{shown}: this board saves nothing (§13)", port)
            return
        values = [int(v) for v in self.params]
        kept = values if self.profile.file is not None else params.saved_form(values)
        saved = (*kept, self.gyro_calibration)
        try:
            self.store.save(saved)
        except AppmodeError as exc:
            self.errors += 1
            self.note(now, "rejected", f"{shown}: save failed: {exc}", port)
            return
        self.note(
            now, "applied", f"{shown}: saved {list(kept)} (gyro calibration {saved[-1]})", port
        )
