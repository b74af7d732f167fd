"""The simulated car's body: velocity response, pose, attitude and battery.

Documented model (all constants here):

- velocity follows its target as a first-order lag with time constant RESPONSE_TAU
  (63 % of a step in 0.1 s, 95 % in 0.3 s), and snaps to the target within SNAP units;
- yaw turns at `yaw_gain` degrees a second per unit of z, clockwise +: the profile's
  `velocity_si` of z in degrees, so that the gyro and the velocity agree (the sheet's
  π mrad/s: 0.18 °/s, z = 500 turns 90 °/s);
- pitch and roll lean with acceleration: TILT_GAIN degrees per unit/s² (nose up while
  speeding up forward, right side down while speeding up to the right);
- or, on a board whose profile ramps (§13, §13.1), velocity is set by `ramp` each tick;
- the battery starts full (12.60 V) and drains IDLE_DRAIN centivolts a second plus
  LOAD_DRAIN per unit of speed; percent is (cV − 1110) × 2 / 3, at most 100, and at least
  0 on the sheet (§3.2).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

RESPONSE_TAU = 0.1
SNAP = 0.5
YAW_GAIN = 0.18
"""°/s of yaw per unit of z on the sheet's board."""
TILT_GAIN = 0.002
FULL_CV = 1260.0
EMPTY_CV = 1110.0
IDLE_DRAIN = 0.02
LOAD_DRAIN = 0.00017


def battery_percent(centivolts: float, floor: bool = True) -> int:
    """§3.2: (cV − 1110) × 2 / 3 in whole percent (truncated, as C divides), at most 100,
    and at least 0 when `floor`."""
    percent = min(100, int((round(centivolts) - round(EMPTY_CV)) * 2 / 3))
    return max(0, percent) if floor else percent


def wrap_degrees(angle: float, low: int = -179, truncate: bool = False) -> int:
    """Whole degrees in low…low + 359, rounded (or truncated, as a C cast does)."""
    if truncate:
        return math.trunc((angle - low) % 360 + low)
    return (round(angle) - low) % 360 + low


@dataclass(slots=True)
class Vehicle:
    """Body state, advanced in fixed steps by `step`."""

    vx: float = 0.0
    vy: float = 0.0
    vz: float = 0.0
    heading: float = 0.0
    east: float = 0.0
    north: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0
    centivolts: float = FULL_CV
    travel_x: float = 0.0
    travel_y: float = 0.0
    travel_z: float = 0.0
    """The body's own x, y, z integrated over time: what the wheel encoders count."""
    yaw_gain: float = YAW_GAIN
    """°/s of yaw per unit of z."""

    def step(self, target: tuple[float, float, float], dt: float, ticks: int = 1) -> None:
        """Advance `ticks` steps of `dt` seconds toward the target velocity (x, y, z),
        each exactly as alone."""
        tx, ty, tz = target
        while ticks > 0:
            old_x, old_y, vz = self.vx, self.vy, self.vz
            if not (old_x or old_y or vz or tx or ty or tz):  # at rest, staying so
                self.rest(ticks, dt)
                return
            if old_x == tx and old_y == ty and vz == tz:  # at the target: the lag keeps it
                self.vx, self.vy, self.vz = tx, ty, tz
                self._move(old_x, old_y, dt, ticks)
                return
            alpha = 1.0 - math.exp(-dt / RESPONSE_TAU)
            vx = old_x + (tx - old_x) * alpha  # each axis a first-order lag, snapped at SNAP
            vy = old_y + (ty - old_y) * alpha
            vz += (tz - vz) * alpha
            self.vx = tx if abs(tx - vx) < SNAP else vx
            self.vy = ty if abs(ty - vy) < SNAP else vy
            self.vz = tz if abs(tz - vz) < SNAP else vz
            self._move(old_x, old_y, dt, 1)
            ticks -= 1

    def rest(self, steps: int, dt: float) -> None:
        """`steps` steps of `dt` at rest: what `step` and `ramp` do then, step by step
        (the battery's idle drain; no tilt)."""
        self.pitch = self.roll = 0.0
        centivolts = self.centivolts
        for _ in range(steps):
            centivolts = max(0.0, centivolts - IDLE_DRAIN * dt)
        self.centivolts = centivolts

    def ramp(
        self,
        pushes: tuple[int | None, ...],
        limit: float,
        step: float,
        coast: float,
        dt: float,
        rounding: Callable[[float], float] = float,
    ) -> None:
        """One control tick of a ramping board (§13.1): an axis pushed by ±1 gains ±step,
        an axis pushed by 0 is set to 0, an axis pushed by None coasts (divided by
        `coast`); then every axis is clamped to ±limit as the firmware does, lower bound
        first (a negative limit holds every axis at it). `rounding` is the chip's float
        (each result stored as it stores it)."""
        old_x, old_y = self.vx, self.vy
        axes = [self.vx, self.vy, self.vz]
        for i, push in enumerate(pushes):
            if push is None:
                value = rounding(axes[i] / coast)
            elif push == 0:
                value = 0.0
            else:
                value = rounding(axes[i] + push * step)
            value = -limit if value < -limit else value
            axes[i] = limit if value > limit else value
        self.vx, self.vy, self.vz = axes
        self._move(old_x, old_y, dt)

    def _move(self, old_x: float, old_y: float, dt: float, ticks: int = 1) -> None:
        """`ticks` steps of `dt` at the velocity the car has: the tilt of the change from
        (old_x, old_y) to it, then pose, travel and battery tick by tick."""
        vx, vy, vz = self.vx, self.vy, self.vz
        self.pitch = (vy - old_y) / dt * TILT_GAIN
        self.roll = (vx - old_x) / dt * TILT_GAIN
        turn = vz * self.yaw_gain * dt
        drain = (IDLE_DRAIN + LOAD_DRAIN * (abs(vx) + abs(vy) + abs(vz))) * dt
        heading, east, north = self.heading, self.east, self.north
        travel_x, travel_y, travel_z = self.travel_x, self.travel_y, self.travel_z
        centivolts = self.centivolts
        cos = sin = 0.0
        for tick in range(ticks):
            if turn or not tick:  # else the heading, and so its cosine and sine, are as they were
                heading = (heading + turn) % 360.0
                rad = math.radians(heading)
                cos, sin = math.cos(rad), math.sin(rad)
            travel_x += vx * dt
            travel_y += vy * dt
            travel_z += vz * dt
            east += (vx * cos + vy * sin) * dt
            north += (vy * cos - vx * sin) * dt
            centivolts = max(0.0, centivolts - drain)
        self.heading, self.east, self.north = heading, east, north
        self.travel_x, self.travel_y, self.travel_z = travel_x, travel_y, travel_z
        self.centivolts = centivolts

    @property
    def battery(self) -> int:
        return battery_percent(self.centivolts)
