"""A WHEELTEC board's chassis port (docs/protocol.md §15): velocity frames in, a status
frame every 50 ms out, as the F1 firmware runs them and its profile's `[chassis]` table
changes.

Frames are ignored, and Flag_Stop set, until the boot delay has passed; a frame with a
wrong tail or XOR is dropped without a word on the wire (the board's log says so). The
velocity asked for holds until the next frame, or until `timeout_ms` without one zeroes
it (0: never, as some firmware copies). Each kind drives what it can: mecanum all three,
differential and Ackermann no sideways motion, Ackermann no turn in place and no radius
under `min_radius`. The status carries the car's velocity, the IMU as the profile's
`imu_axes` remap the chip's (F1's `y,-x,z`: the body's x forward, y left, z up), gyro z
sent as 0 while Flag_Stop is set, and the battery in mV.
"""

from __future__ import annotations

import math

from appmode.board.core import Core
from appmode.board.vehicle import TILT_GAIN
from appmode.protocol import chassis
from appmode.protocol.chassis_profile import ChassisSpec

PORT = "chassis"
"""The port, as the board's log names it."""
PERIOD_MS = round(chassis.STATUS_PERIOD * 1000)
TICK_MS = 10
"""The board's control tick (firmware.TICK_MS)."""
SELF_TEST = 100
"""mm/s forward of the self-test drive (F2, F3)."""
GRAVITY = 9.8


NONE = ChassisSpec("mec")
"""What a board without a chassis port holds in its place: it hears and sends nothing."""


class ChassisPort:
    """The chassis port's frames, its velocity in force and its status frames; on a
    board whose profile has none (`spec` None), a port that hears and sends nothing."""

    def __init__(self, core: Core, spec: ChassisSpec | None) -> None:
        self.core = core
        self.present = spec is not None
        self.spec = spec if spec is not None else NONE
        self.decoder = chassis.CommandDecoder()
        self.status_ms: float = PERIOD_MS if spec is not None else math.inf
        """When the next status frame goes out, in ms from boot (infinity: never)."""
        self.asked: tuple[int, int, int] | None = None
        """The velocity of the last frame taken (mm/s, mm/s, mrad/s), None: none in force."""
        self.asked_ms = 0
        """When it was taken, in ms from boot."""
        self.out = bytearray()

    @property
    def flag_stop(self) -> bool:
        return self.core.tick_ms < self.spec.boot_ms

    def receive(self, data: bytes, now: float) -> None:
        """Host bytes that arrived at `now`."""
        core = self.core
        if not self.present:
            return  # nothing is wired to it
        for event in self.decoder.feed(data):
            if isinstance(event, chassis.Junk):
                core.note(now, "rejected", f"{event} (dropped, as the firmware does)", PORT)
            elif isinstance(event, chassis.Command):
                if self.flag_stop:
                    core.note(now, "rejected", f"{event}: ignored while booting", PORT)
                    continue
                self.asked = self._drivable(event)
                self.asked_ms = core.tick_ms
                core.note(now, "applied", str(event), PORT)

    def _drivable(self, frame: chassis.Command) -> tuple[int, int, int]:
        """What the car's kind makes of a frame's velocity (mm/s, mm/s, mrad/s)."""
        spec = self.spec
        top = round(spec.max_speed * chassis.MILLI)
        vx, vy, wz = (max(-top, min(top, v)) for v in (frame.vx, frame.vy, frame.wz))
        if spec.kind == "mec":
            return (vx, vy, wz)
        if spec.kind == "diff":
            return (vx, 0, wz)
        if not vx:
            return (0, 0, 0)  # an Ackermann car cannot turn in place
        tightest = abs(vx) / spec.min_radius  # mrad/s at the smallest radius
        return (vx, 0, round(math.copysign(min(abs(wz), tightest), wz)))

    def target(self, ms: int) -> tuple[float, float, float] | None:
        """The velocity the chassis port asks for at `ms`, in the car's units (x right, y
        forward, z clockwise); None: it asks for nothing (the APP port drives)."""
        spec = self.spec
        if spec.self_test_ms and spec.boot_ms <= ms < spec.boot_ms + spec.self_test_ms:
            return (0.0, float(SELF_TEST), 0.0)
        if self.asked is None:
            return None
        if spec.timeout_ms and ms - self.asked_ms >= spec.timeout_ms:
            self.asked = None
            return (0.0, 0.0, 0.0)
        vx, vy, wz = self.asked
        return (float(-vy), float(vx), float(-wz))

    def drives(self) -> bool:
        """The port asks the car to move now."""
        return self.present and any(self.target(self.core.tick_ms) or ())

    def drive(self, ticks: int, tick: float, at_once: bool) -> bool:
        """`ticks` control ticks of `tick` seconds toward what the port asks for (in one
        step `at_once`); whether it asks for anything (else the APP port drives)."""
        core = self.core
        asked = self.target(core.tick_ms) if self.present else None
        if asked is None:
            return False
        core.target_velocity = asked
        if at_once:
            core.vehicle.step(asked, ticks * tick)
        else:
            core.vehicle.step(asked, tick, ticks)
        return True

    def last_tick(self, last: float) -> float:
        """The last control tick (by `last`) that the tick before can stand for: none
        after a status frame's or a change of what the port asks for."""
        if not self.present:
            return last
        return min(last, self.status_ms, self.next_change_ms() - TICK_MS)

    def next_change_ms(self) -> float:
        """When what the port asks for next changes by itself (the boot's end, the
        self-test's, a time-out), in ms from boot; infinity: not by itself."""
        spec, ms = self.spec, self.core.tick_ms
        changes = [spec.boot_ms, spec.boot_ms + spec.self_test_ms]
        if self.asked is not None and spec.timeout_ms:
            changes.append(self.asked_ms + spec.timeout_ms)
        return min((c for c in changes if c >= ms), default=math.inf)

    def _sent(self, body: tuple[float, float, float]) -> tuple[int, int, int]:
        """A vector in the body's axes as the status frame sends it: the chip mounted as
        on F1 (its x the body's −y, its y the body's x), then the profile's remap."""
        chip = (-body[1], body[0], body[2])
        x, y, z = (round(sign * chip[axis]) for sign, axis in self.spec.axes())
        return (x, y, z)

    def skip(self, ms: int) -> None:
        """The board caught up at once to `ms` (it was stalled): the status frames due
        meanwhile are not sent."""
        if self.status_ms < ms:
            self.status_ms += -(-(ms - self.status_ms) // PERIOD_MS) * PERIOD_MS

    def send_status(self) -> None:
        """The status frame due now."""
        vehicle = self.core.vehicle
        stop = self.flag_stop
        velocity = (round(vehicle.vy), round(-vehicle.vx), round(-vehicle.vz))
        milli = 1 / chassis.MILLI
        forward = vehicle.pitch / TILT_GAIN * milli  # m/s² (the body's tilt is its lean)
        left = -vehicle.roll / TILT_GAIN * milli
        scale = chassis.ACCEL_PER_MS2
        turn = -vehicle.vz * milli / chassis.GYRO_RAD_PER_COUNT
        accel = self._sent((forward * scale, left * scale, GRAVITY * scale))
        gyro = self._sent((0.0, 0.0, 0.0 if stop else turn))
        mv = round(vehicle.centivolts * 10)
        self.out += chassis.status(int(stop), velocity, accel, gyro, mv)
        self.status_ms += PERIOD_MS
