"""Dead reckoning from the board's reported velocity, with no I/O: each velocity the car
reports (REP 103's forward, left, counter-clockwise; m/s, rad/s: `twist.Twist`)
integrated from report to report. Its error grows with the distance driven: the pose's
variance is stated as (DRIFT × distance)² plus a floor, for a consumer that fuses it."""

from __future__ import annotations

import math
from dataclasses import dataclass

from appmode.protocol.twist import Twist


@dataclass(frozen=True, slots=True)
class Pose2D:
    """Where the car is in `odom` (metres, radians counter-clockwise) and how it moves
    in `base_link` (m/s forward and left, rad/s counter-clockwise)."""

    x: float
    y: float
    yaw: float
    forward: float
    left: float
    turn: float


DRIFT = 0.05
"""The standard deviation of the pose per metre driven (x, y in metres, yaw in radians):
a wheeled car's dead reckoning drifts by a few per cent."""
FLOOR = 1e-4
GAP = 0.5
"""Seconds between two records past which the car's motion in between is unknown: the
next record starts a new step (the pose is not pushed across a gap in the telemetry)."""


class Odometry:
    """The car's pose in `odom`, integrated from the velocities reported."""

    def __init__(self) -> None:
        self.pose = Pose2D(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        self.distance = 0.0
        self._at: float | None = None

    def step(self, at: float, velocity: Twist) -> Pose2D:
        """A velocity reported at `at` (seconds): the pose after it, moved by the mean of
        this velocity and the last over the time between them."""
        forward, left, turn = velocity.forward, velocity.left, velocity.turn
        last = self.pose
        dt = 0.0 if self._at is None or not 0 < at - self._at <= GAP else at - self._at
        self._at = at
        mean_forward, mean_left = (forward + last.forward) / 2, (left + last.left) / 2
        mean_turn = (turn + last.turn) / 2
        heading = last.yaw + mean_turn * dt / 2
        dx = (mean_forward * math.cos(heading) - mean_left * math.sin(heading)) * dt
        dy = (mean_forward * math.sin(heading) + mean_left * math.cos(heading)) * dt
        self.distance += math.hypot(dx, dy)
        yaw = math.remainder(last.yaw + mean_turn * dt, math.tau)
        self.pose = Pose2D(last.x + dx, last.y + dy, yaw, forward, left, turn)
        return self.pose

    @property
    def variance(self) -> float:
        return FLOOR + (DRIFT * self.distance) ** 2
