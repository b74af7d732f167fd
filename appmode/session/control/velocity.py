"""A twist on the control port, with no I/O: the velocity frame's fields in the board's
units (the profile's `velocity_si`) — x right, y forward, z clockwise on omni and
mecanum cars; on differential ones duties of max_speed in ‰, as §9.1 takes them — and
back, the signs of the motion a frame in force asks for."""

from __future__ import annotations

from appmode.protocol import control
from appmode.protocol.params import DriveType
from appmode.protocol.twist import Twist


def frame_fields(
    twist: Twist, drive: DriveType, si: tuple[float, float], max_speed: int | None
) -> dict[str, int]:
    """The velocity frame's fields (ControlHost.velocity's keywords) for `twist`;
    `max_speed` is needed on a differential car (its frames take duties of it)."""
    x, y, z = twist.units(si)
    if not drive.differential:
        return {k: _within(v, control.U16) for k, v in (("x", x), ("y", y), ("z", z))}
    if not max_speed or max_speed < 0:
        raise ValueError("a differential car's frames are duties of max_speed: read it first")
    duty_y, duty_z = y / max_speed * 1000, z / max_speed * 1000
    if drive is DriveType.DIFF_GYRO:
        return {
            "left": _within(duty_y + duty_z, control.MAX_DUTY),
            "right": _within(duty_y - duty_z, control.MAX_DUTY),
        }
    return {"y": _within(duty_y, control.MAX_DUTY), "z": _within(duty_z, control.MAX_DUTY)}


def _within(value: float, limit: int) -> int:
    """`value` rounded, within ±limit (clamped first: no number is too large to round)."""
    return round(max(-limit, min(limit, value)))
