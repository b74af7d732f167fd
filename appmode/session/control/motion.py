"""What a motion of the keys or a stick is in a velocity frame, for each drive type."""

from __future__ import annotations

from appmode.protocol import control
from appmode.protocol.directions import Motion
from appmode.protocol.params import DriveType


def velocity_for(motion: Motion, speed: int, drive: DriveType) -> dict[str, int]:
    """The velocity frame's fields (`ControlHost.velocity` keywords) that drive `motion`
    at `speed` on `drive`: x, y, z on omni and mecanum, y and z duties on diff, left
    and right duties on diff-gyro (each within ±MAX_DUTY)."""
    if not drive.differential:
        x, y, z = (round(f * speed) for f in motion.holonomic)
        return {"x": x, "y": y, "z": z}
    fy, fz = (f * speed for f in motion.differential)

    def duty(value: float) -> int:
        return max(-control.MAX_DUTY, min(control.MAX_DUTY, round(value)))

    if drive is DriveType.DIFF_GYRO:
        return {"left": duty(fy + fz), "right": duty(fy - fz)}
    return {"y": duty(fy), "z": duty(fz)}
