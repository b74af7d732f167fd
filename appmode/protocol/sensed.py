"""What a board's records say of its motion, as a twist in SI, with no I/O.

An A record carries the body velocity signed (the sheet's `x`, `y`, `z`) or as
magnitudes (the reference firmware's `abs_x`, `abs_y`: |0.7·x|, |0.7·y|), each field
`scale` × the velocity unit; a profile's `velocity_si` says what a unit is. Magnitudes
take their signs from the motion in force, which the control port's firmware applies as
sent (docs/protocol.md §13.1: no ramp); a turn no A field carries is the rate of the B
record's yaw (the gyro's), over the last YAW_WINDOW seconds."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from appmode.protocol import control
from appmode.protocol.layouts import Layout
from appmode.protocol.params import DriveType
from appmode.protocol.profile_file import Field
from appmode.protocol.twist import Twist

YAW_WINDOW = 0.5
"""Seconds of B records a turn rate is taken over (their yaw is in whole degrees)."""
AXES = "xyz"


class Sensing:
    """How one layout's records give the car's twist, or why they cannot."""

    def __init__(self, layout: Layout) -> None:
        self.si = layout.profile.velocity_si
        named = {field.name: (i, field) for i, field in enumerate(layout.a_fields)}
        self.axes: list[tuple[int, Field] | None] = []
        """Per axis (x, y, z): the A field that carries it, signed or as a magnitude."""
        for axis in AXES:
            found = named.get(axis)
            if found is None or not found[1].signed:
                found = named.get(f"abs_{axis}")
            self.axes.append(found)
        self.yaw = next((i for i, f in enumerate(layout.b_fields) if f.name == "yaw"), None)
        """The B field of the yaw, in degrees clockwise (for a turn no A field carries)."""
        self.needs_signs = any(found is not None and not found[1].signed for found in self.axes)
        """Some axis comes as a magnitude: its sign is the motion in force."""
        self.turn_from_yaw = self.axes[2] is None and self.yaw is not None
        self.name = layout.profile.name

    @property
    def gap(self) -> str | None:
        """Why the records give no twist (None: they do)."""
        if self.axes[0] is None or self.axes[1] is None:
            return f"the {self.name} profile's A record carries no velocity of x and y"
        if self.axes[2] is None and self.yaw is None:
            return f"the {self.name} profile's records carry no turn (no z, no yaw)"
        return None

    def twist(
        self,
        values: Sequence[int],
        signs: tuple[float, float, float] | None,
        yaw_rate: float | None,
    ) -> Twist | None:
        """The twist an A record's `values` say, given the signs of the motion in force
        (None: unknown) and the yaw's rate in °/s clockwise; None when they cannot say."""
        if self.gap is not None or (self.needs_signs and signs is None):
            return None
        units: list[float] = []
        for axis, found in enumerate(self.axes):
            if found is None:
                if yaw_rate is None:
                    return None
                units.append(math.radians(yaw_rate) / self.si[1])
                continue
            index, field = found
            value = values[index] / field.scale
            if not field.signed:
                assert signs is not None
                value = math.copysign(abs(value), signs[axis]) if signs[axis] else 0.0
            units.append(value)
        return Twist.from_units(units[0], units[1], units[2], self.si)


Frame = control.VelocityFrame | control.MotorFrame | control.PositionFrame


def signs_in_force(
    frame: Frame | None, drive: DriveType | None
) -> tuple[float, float, float] | None:
    """The signs (−1, 0, 1) of x, y and z that the frame in force drives (None: not
    known: the drive type is not, or the frame is no velocity frame)."""
    if frame is None:
        return (0.0, 0.0, 0.0)
    if drive is None or not isinstance(frame, control.VelocityFrame):
        return None
    a, b, c = frame.values
    if drive is DriveType.DIFF_GYRO:  # left and right duties
        b, c = a + b, a - b
        a = 0
    elif drive.differential:  # reserved, y, z
        a = 0
    return (_sign(a), _sign(b), 0.0 if frame.angle else _sign(c))


def _sign(value: int) -> float:
    return float((value > 0) - (value < 0))


def yaw_rate(points: Sequence[tuple[float, float]], at: float) -> float | None:
    """The yaw's rate in °/s at `at`, from (time, yaw in degrees) points in time order:
    over the points of the YAW_WINDOW before `at`, each step unwrapped across ±180°."""
    window = [(t, yaw) for t, yaw in points if at - YAW_WINDOW <= t <= at]
    if len(window) < 2 or window[-1][0] - window[0][0] <= 0:
        return None
    turned = sum(math.remainder(b[1] - a[1], 360.0) for a, b in itertools.pairwise(window))
    return turned / (window[-1][0] - window[0][0])


@dataclass(frozen=True, slots=True)
class Inertial:
    """What a board's IMU reports, in SI and REP 103's axes (x forward, y left, z up):
    the angular velocity (rad/s), the linear acceleration (m/s², gravity included) and,
    where the same report carries it, the battery's voltage."""

    angular_velocity: tuple[float, float, float]
    acceleration: tuple[float, float, float]
    volts: float | None = None
