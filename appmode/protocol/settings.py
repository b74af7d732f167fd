"""The control port's ten settings and its reads (docs/protocol.md §10, §11): one table.

Settings 1–9 are the APP port's nine parameters (`params.PARAMS`: their names, ranges
and defaults come from there); setting 10, gyro_calibration, exists only on this port.
The codec, the board, the host and the docs all read these tables.
"""

from __future__ import annotations

from dataclasses import dataclass

from appmode.errors import InvalidValue
from appmode.protocol import params


@dataclass(frozen=True, slots=True)
class Setting:
    """One setting of a mode-`80` frame: `FF FE 80 80 <id> v3 v2 v1 v0 00`."""

    id: int
    name: str
    width: int
    """Value bytes the sheet gives it: 2 (TX[7..8]) or 4 (TX[5..8]); the frame always
    carries 4, and the upper two of a 2-byte setting must be 0."""
    maximum: int
    default: int
    param: int | None
    """The APP parameter it is (`{n:v}`), or None for gyro_calibration."""

    @property
    def read_id(self) -> int:
        """The SS that reads it (§11)."""
        return READ_BASE + self.id

    @property
    def range_text(self) -> str:
        return f"0–{self.maximum}"


READ_BASE = 0x10
_WIDTHS = (2, 2, 4, 4, 4, 4, 4, 4, 4)
SETTINGS: tuple[Setting, ...] = (
    *(
        Setting(p.index + 1, p.name, width, p.maximum, p.default, p.index)
        for p, width in zip(params.PARAMS, _WIDTHS, strict=True)
    ),
    Setting(10, "gyro_calibration", 2, params.U16, 0, None),
)
BY_NAME: dict[str, Setting] = {s.name: s for s in SETTINGS}
BY_ID: dict[int, Setting] = {s.id: s for s in SETTINGS}
GYRO_CALIBRATION = BY_NAME["gyro_calibration"]
RECALIBRATE = 0xFFFF
"""gyro_calibration saved as this: calibrate again at the next power-up (§10)."""


def value_error(setting: Setting, value: int) -> str | None:
    """Why `value` cannot be `setting`, or None when it can."""
    if not 0 <= value <= setting.maximum:
        where = f"{setting.name} (setting {setting.id:02X})"
        return f"{where} must be in {setting.range_text}, not {value}"
    if setting.param is not None:
        return params.value_error(setting.param, value)
    return None


def lookup(key: str) -> Setting:
    """A setting by name or by its id (`1`–`10`, or hex `0x0A`); ValueError lists them."""
    text = key.strip().lower()
    number = None
    if text.startswith("0x"):
        try:
            number = int(text, 16)
        except ValueError:
            number = None
    else:
        number = params.whole(text)
    if number is not None and number in BY_ID:
        return BY_ID[number]
    if text in BY_NAME:
        return BY_NAME[text]
    names = ", ".join(s.name for s in SETTINGS)
    raise InvalidValue(f"unknown setting {key!r}: use 1–{len(SETTINGS)} or one of {names}")


# ---------------------------------------------------------------- load and save (SS 00)


@dataclass(frozen=True, slots=True)
class StoreOp:
    """`FF FE 80 80 00 80 00 00 <code> 00`: load, defaults or save (§10)."""

    code: int
    name: str
    meaning: str


STORE_OPS: tuple[StoreOp, ...] = (
    StoreOp(1, "load", "load the saved settings into the running copy"),
    StoreOp(2, "defaults", "load the factory defaults into the running copy"),
    StoreOp(3, "save", "save the running copy"),
)
STORE_BY_CODE: dict[int, StoreOp] = {op.code: op for op in STORE_OPS}
STORE_BY_NAME: dict[str, StoreOp] = {op.name: op for op in STORE_OPS}
STORE_ID = 0x00
STORE_PREFIX = 0x8000
"""TX[5..6] of a load or save frame."""

# ---------------------------------------------------------------- reads (§11)

WHEELS = "abcd"


@dataclass(frozen=True, slots=True)
class Read:
    """One readable value: the SS that asks for it, the id of its `#` reply, its sign."""

    ss: int
    reply_id: int
    name: str
    signed: bool
    meaning: str


PENDING_ANGLE = 0x20
SPEED_BASE = 0x21
POSITION_BASE = 0x25

READS: tuple[Read, ...] = (
    *(Read(s.read_id, s.id, s.name, False, f"setting {s.id}") for s in SETTINGS),
    Read(PENDING_ANGLE, PENDING_ANGLE, "pending_angle", True, "pending rotation, 0.1°"),
    *(
        Read(SPEED_BASE + i, SPEED_BASE + i, f"speed_{w}", True, f"wheel {w.upper()} speed")
        for i, w in enumerate(WHEELS)
    ),
    *(
        Read(
            POSITION_BASE + i,
            POSITION_BASE + i,
            f"position_{w}",
            True,
            f"wheel {w.upper()} position",
        )
        for i, w in enumerate(WHEELS)
    ),
)
READ_BY_SS: dict[int, Read] = {r.ss: r for r in READS}
READ_BY_REPLY: dict[int, Read] = {r.reply_id: r for r in READS}
READ_BY_NAME: dict[str, Read] = {r.name: r for r in READS}


def read_named(key: str) -> Read:
    """A read by name (a setting's, `pending_angle`, `speed_a`…`position_d`) or SS in hex."""
    text = key.strip().lower()
    if text in READ_BY_NAME:
        return READ_BY_NAME[text]
    if text.startswith("0x"):
        try:
            ss = int(text, 16)
        except ValueError:
            ss = -1
        if ss in READ_BY_SS:
            return READ_BY_SS[ss]
    names = ", ".join(READ_BY_NAME)
    raise InvalidValue(f"unknown read {key!r}: use one of {names}")
