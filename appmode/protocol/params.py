"""The nine board parameters and the system-mode bits (docs/protocol.md §5, §6): one table,
the sheet's profile file's.

The codec, the board model, the host, the console and the docs all read these tables;
nothing else in appmode spells out a parameter's name, range or default.
"""

from __future__ import annotations

from collections.abc import Sequence

from appmode.errors import InvalidValue
from appmode.protocol import profile_file
from appmode.protocol.drive_types import DRIVE_NAMES as DRIVE_NAMES
from appmode.protocol.drive_types import DriveType as DriveType

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from typing import NamedTuple
else:
    from appmode.protocol.tuples import NamedTuple

U16 = 0xFFFF
U32 = 0xFFFF_FFFF


class Param(NamedTuple):
    """One parameter of the `{n:v}` / `{C…}$` set (a table row: a named tuple is cheaper to
    load than a dataclass, and `appmode params --help` lists these)."""

    index: int  # type: ignore[assignment]  # the field shadows tuple.index(), on purpose
    name: str
    label: str
    maximum: int
    default: int
    minimum: int = 0

    @property
    def range_text(self) -> str:
        return f"{self.minimum}–{self.maximum}"


SPECS: tuple[profile_file.ParamSpec, ...] = profile_file.shipped("sheet").params
"""The sheet's nine as its file declares them (`param_values` reads any profile's)."""
PARAMS: tuple[Param, ...] = tuple(
    Param(i, p.name, p.label, p.maximum, p.default, p.minimum) for i, p in enumerate(SPECS)
)
"""The sheet's nine, from its profile (`protocol/profiles/sheet.toml`)."""
PARAM_COUNT = len(PARAMS)
BY_NAME: dict[str, Param] = {p.name: p for p in PARAMS}
DEFAULTS: tuple[int, ...] = tuple(p.default for p in PARAMS)
MAX_SPEED = BY_NAME["max_speed"].index
SYSTEM_MODE = BY_NAME["system_mode"].index


DRIVE_MASK = 0b111
_DRIVES: dict[int, DriveType] = {drive.value: drive for drive in DriveType}


class ModeBit(NamedTuple):
    """One named bit (or field) of system_mode."""

    bit: int
    name: str
    meaning: str
    saved: bool = True


MODE_BITS: tuple[ModeBit, ...] = (
    ModeBit(3, "gyro_calibration", "gyro calibration at power-up"),
    ModeBit(4, "heading_correction", "gyro heading correction while x and y are 0"),
    ModeBit(6, "encoder_report", "encoder report on UART2", saved=False),
    ModeBit(7, "app_mode", "command mode: 0 control, 1 APP", saved=False),
    ModeBit(8, "motor_reverse", "motor reverse"),
    ModeBit(9, "encoder_reverse", "encoder reverse"),
    ModeBit(10, "steering_reverse", "steering reverse"),
    ModeBit(11, "gyro_reverse", "gyro reverse"),
)
MODE_BIT: dict[str, int] = {b.name: 1 << b.bit for b in MODE_BITS}
UNSAVED_MASK = sum(1 << b.bit for b in MODE_BITS if not b.saved)


def drive_type(system_mode: int) -> DriveType | None:
    """The drive type in bits 0–2, or None when the field holds an invalid value (4–7)."""
    return _DRIVES.get(system_mode & DRIVE_MASK)


def value_error(index: int, value: int) -> str | None:
    """Why `value` cannot be parameter `index`, or None when it can."""
    if not 0 <= index < PARAM_COUNT:
        return f"no parameter {index}: indices are 0–{PARAM_COUNT - 1}"
    param = PARAMS[index]
    if not param.minimum <= value <= param.maximum:
        return f"{param.name} (parameter {index}) must be in {param.range_text}, not {value}"
    if index == SYSTEM_MODE and drive_type(value) is None:
        return (
            f"system_mode {value} has drive type {value & DRIVE_MASK} in bits 0–2; "
            f"valid drive types are 0–3"
        )
    return None


def check_value(index: int, value: int) -> None:
    """Raise ValueError naming the parameter and its range when `value` is not allowed."""
    error = value_error(index, value)
    if error is not None:
        raise InvalidValue(error)


def whole(text: str) -> int | None:
    """`text` as a whole number if it is one written in ASCII digits (not `١٢`, not `+1`),
    short enough for Python to read (4,000 digits); else None."""
    text = text.strip()
    if text.isascii() and text.isdigit() and len(text) <= 4000:
        return int(text)
    return None


_BOUNDS = tuple((p.minimum, p.maximum) for p in PARAMS)


def values_error(values: Sequence[int]) -> str | None:
    """Why `values` is not a valid set of the nine parameters, or None."""
    if len(values) != PARAM_COUNT:
        return f"expected {PARAM_COUNT} parameters, got {len(values)}"
    # the common case, quickly (every C record a host decodes comes through here)
    if all(lo <= v <= hi for v, (lo, hi) in zip(values, _BOUNDS, strict=True)) and (
        values[SYSTEM_MODE] & DRIVE_MASK
    ) <= max(DriveType):
        return None
    for index, value in enumerate(values):
        error = value_error(index, value)
        if error is not None:
            return error
    return None


def saved_form(values: Sequence[int]) -> tuple[int, ...]:
    """The parameters as the board saves them: system_mode's unsaved bits cleared."""
    out = list(values)
    out[SYSTEM_MODE] &= ~UNSAVED_MASK
    return tuple(out)
