"""The drive types system_mode's bits 0–2 select, and their names on the command line:
no parameter tables here, so the commands' options can name them at start-up."""

from __future__ import annotations

from enum import IntEnum

from appmode.errors import InvalidValue


class DriveType(IntEnum):
    """System-mode bits 0–2."""

    OMNI = 0
    MECANUM = 1
    DIFF = 2
    DIFF_GYRO = 3

    @property
    def cli_name(self) -> str:
        return _DRIVE_CLI_NAMES[self]

    @property
    def differential(self) -> bool:
        return self in (DriveType.DIFF, DriveType.DIFF_GYRO)

    @classmethod
    def from_cli_name(cls, name: str) -> DriveType:
        for drive, text in _DRIVE_CLI_NAMES.items():
            if text == name:
                return drive
        choices = ", ".join(_DRIVE_CLI_NAMES.values())
        raise InvalidValue(f"unknown drive type {name!r}: choose one of {choices}")


_DRIVE_CLI_NAMES = {
    DriveType.OMNI: "omni",
    DriveType.MECANUM: "mecanum",
    DriveType.DIFF: "diff",
    DriveType.DIFF_GYRO: "diff-gyro",
}
DRIVE_NAMES: tuple[str, ...] = tuple(_DRIVE_CLI_NAMES.values())
