"""A profile file's `[chassis]` table: a WHEELTEC board's chassis port (protocol/chassis.py)
and what differs between the copies of its firmware. The defaults are the F1 board's
(the STM32F407 "mini car" firmware): docs/protocol.md §15 names the others."""

from __future__ import annotations

from collections.abc import Callable

from appmode.protocol.profile_checks import number, whole

TYPE_CHECKING = False  # as in profile_file: `decode` reads profiles, and starts fast
if TYPE_CHECKING:
    from typing import Any, NamedTuple
else:
    from appmode.protocol.tuples import NamedTuple

KINDS = {
    "mec": "mecanum: forward, sideways and turn as asked",
    "akm": "Ackermann: no sideways motion; a turn steers, within its minimum radius",
    "diff": "differential or tank: no sideways motion",
}
KEYS = {"kind", "timeout_ms", "boot_ms", "self_test_ms", "min_radius", "max_speed", "imu_axes"}
F1_AXES = "y,-x,z"
"""F1–F4's remap of the IMU chip's axes: the status frame's x is the chip's y, its y the
chip's −x, its z the chip's z (on those boards: the car's forward, left and up)."""


class ChassisSpec(NamedTuple):
    """How a WHEELTEC board's chassis port behaves."""

    kind: str
    """`mec`, `akm` or `diff` (KINDS)."""
    timeout_ms: int = 1000
    """The velocity is zeroed this long after the last valid frame (F1, F4); 0: never (F2,
    and F3 at its default security level): the car keeps its last velocity for good."""
    boot_ms: int = 10_000
    """Frames are ignored, and Flag_Stop is set, this long after power-up (F1 and F3:
    1000 ticks at 100 Hz; F2 750)."""
    self_test_ms: int = 0
    """The car drives slowly forward this long after the boot delay (F2, F3: about 2000);
    0: no self-test (F1)."""
    min_radius: float = 0.35
    """Ackermann: the smallest turning radius, in m (F1's 0.35)."""
    max_speed: float = 3.5
    """m/s (and rad/s) past which the car's wheels cannot follow."""
    imu_axes: str = F1_AXES
    """What the status frame's IMU x, y and z are, as the chip's axes (`y,-x,z`: F1's
    remap); the simulated chip is mounted as on F1, so another remap sends other axes."""

    def axes(self) -> tuple[tuple[int, int], ...]:
        """`imu_axes` as (sign, chip axis index) for x, y and z."""
        return tuple(
            (-1 if a[0] == "-" else 1, "xyz".index(a[-1])) for a in self.imu_axes.split(",")
        )


def chassis_spec(
    data: dict[str, Any], base: ChassisSpec | None, problem: Callable[[str], None]
) -> ChassisSpec | None:
    """The `[chassis]` table of a profile file's TOML `data` (else its base's), checked."""
    table = data.get("chassis")
    if table is None:
        return base
    if not isinstance(table, dict):
        problem('[chassis] is a table: kind = "mec", timeout_ms = 1000, …')
        return base
    for key in sorted(set(table) - KEYS):
        problem(f"chassis.{key}: unknown; the keys are {', '.join(sorted(KEYS))}")
    kind = table.get("kind", base.kind if base else None)
    known = kind in KINDS
    if not known:
        problem(f"chassis.kind = {kind!r}: one of {', '.join(KINDS)}")
    values: dict[str, Any] = {**(_fields(base) if base else {}), "kind": kind}
    for key, limit in (("timeout_ms", 60_000), ("boot_ms", 120_000), ("self_test_ms", 60_000)):
        if key in table:
            value = table[key]
            if not whole(value) or not 0 <= value <= limit:
                problem(f"chassis.{key} = {value!r}: whole milliseconds, 0 to {limit}")
                continue
            values[key] = int(value)
    if "imu_axes" in table:
        axes = table["imu_axes"]
        parts = axes.split(",") if isinstance(axes, str) else []
        if sorted(p.lstrip("-") for p in parts) != ["x", "y", "z"]:
            problem(f"chassis.imu_axes = {axes!r}: the chip's x, y and z in some order, each "
                    f"maybe negated, such as {F1_AXES!r}")  # fmt: skip
        else:
            values["imu_axes"] = axes
    for key in ("min_radius", "max_speed"):
        if key in table:
            value = table[key]
            if not number(value) or not 0 < value <= 100:
                problem(f"chassis.{key} = {value!r}: a number over 0, up to 100")
                continue
            values[key] = float(value)
    return ChassisSpec(**values) if known else base


def _fields(spec: ChassisSpec) -> dict[str, Any]:
    return spec._asdict()
