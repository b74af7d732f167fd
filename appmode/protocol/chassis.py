"""The WHEELTEC chassis port's grammar both ways, with no I/O (docs/protocol.md §15).

WHEELTEC's ROS cars take 11-byte velocity frames, `7B mode 00 Vx Vy ωz XOR 7D`, and send
a 24-byte status frame every 50 ms: `7B Flag_Stop Vx Vy ωz ax ay az gx gy gz mV XOR 7D`,
every number an int16 big-endian, velocities × 1000 of m/s and rad/s (REP 103: x forward,
y left, z counter-clockwise). The XOR covers every byte before it, the header included.
The board drops a frame with a wrong tail or XOR silently: nothing is acknowledged.

`command` and `status` make the bytes; `CommandDecoder` (what the board reads) and
`StatusDecoder` (what the host reads) find frames as the vendor's driver does — a frame
starts at 7B and is taken when its tail and XOR are right — and, unlike it, look for the
next frame at the next 7B of the bytes they held (a 7B inside a frame's data is no
start), give every byte to exactly one event, and never raise on bytes.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

from appmode.protocol.bulk import linear
from appmode.protocol.twist import Twist

HEAD, TAIL = 0x7B, 0x7D
COMMAND_LEN, STATUS_LEN = 11, 24
BAUD = 115200
STATUS_PERIOD = 0.05
"""Seconds between status frames (the board's 20 Hz task)."""
ACCEL_PER_MS2 = 1671.84
"""Raw accelerometer counts per m/s² (±2 g), as the vendor's driver divides them."""
GYRO_RAD_PER_COUNT = 0.00026644
"""rad/s per raw gyroscope count (±500 °/s), as the vendor's driver multiplies them."""
MILLI = 1000
INT16 = 32767
MAX_RUN = 64
"""Longest run of bytes outside any frame reported as one event."""
OUTSIDE = "bytes outside any frame"
NORMAL = 0
MODES = {0: "normal", 1: "recharge", 2: "recharge", 3: "docking", 4: "lights"}
"""Byte 1 of a command frame: what the velocities are for (the docking modes' cars only)."""
_COMMAND = struct.Struct(">BBBhhh")
_STATUS = struct.Struct(">BBhhhhhhhhhh")


def xor(data: bytes | bytearray) -> int:
    """The frames' check byte: the XOR of `data`."""
    check = 0
    for byte in data:
        check ^= byte
    return check


def milli(value: float) -> int:
    """m/s or rad/s as the frame's int16 of thousandths: rounded, within ±32.767 (the
    vendor's driver truncates with no range check: 40 m/s would wrap to −25.5)."""
    return round(max(-INT16, min(INT16, value * MILLI)))


@dataclass(frozen=True, slots=True)
class Command:
    """A velocity frame, host → board: mm/s forward and left, mrad/s counter-clockwise."""

    vx: int
    vy: int
    wz: int
    mode: int = NORMAL
    reserved: int = 0
    """Byte 2: 0 (a security byte on brushless boards: 1 keeps a car moving without frames)."""
    raw: bytes = field(default=b"", compare=False, repr=False)

    @property
    def twist(self) -> Twist:
        return Twist(self.vx / MILLI, self.vy / MILLI, self.wz / MILLI)

    def __str__(self) -> str:
        mode = "" if self.mode == NORMAL else f" mode {self.mode} ({MODES.get(self.mode, '?')})"
        return f"velocity {self.twist}{mode}"


@dataclass(frozen=True, slots=True)
class Status:
    """A status frame, board → host, as the wire has it (raw IMU counts, mV)."""

    flag_stop: int
    vx: int
    vy: int
    wz: int
    accel: tuple[int, int, int]
    gyro: tuple[int, int, int]
    millivolts: int
    raw: bytes = field(default=b"", compare=False, repr=False)

    @property
    def twist(self) -> Twist:
        """The car's velocity, as its wheels count it."""
        return Twist(self.vx / MILLI, self.vy / MILLI, self.wz / MILLI)

    @property
    def acceleration(self) -> tuple[float, float, float]:
        """m/s², x forward, y left, z up (gravity reads +9.8 on a level car)."""
        x, y, z = self.accel
        return (x / ACCEL_PER_MS2, y / ACCEL_PER_MS2, z / ACCEL_PER_MS2)

    @property
    def angular_velocity(self) -> tuple[float, float, float]:
        """rad/s about x, y, z (counter-clockwise +)."""
        x, y, z = self.gyro
        return (x * GYRO_RAD_PER_COUNT, y * GYRO_RAD_PER_COUNT, z * GYRO_RAD_PER_COUNT)

    @property
    def volts(self) -> float:
        return self.millivolts / MILLI

    def __str__(self) -> str:
        ax, ay, az = self.acceleration
        gx, gy, gz = self.angular_velocity
        stop = " STOP" if self.flag_stop else ""
        return (
            f"status{stop} {self.twist}  accel {ax:+.2f} {ay:+.2f} {az:+.2f} m/s²  "
            f"gyro {gx:+.3f} {gy:+.3f} {gz:+.3f} rad/s  battery {self.volts:.2f} V"
        )


@dataclass(frozen=True, slots=True)
class Junk:
    """Bytes that are no frame: outside any, a frame with a wrong XOR, or cut off."""

    raw: bytes
    reason: str = OUTSIDE

    def __str__(self) -> str:
        return f"{self.reason}: {self.raw.hex(' ')}"


Event = Command | Status | Junk


def command(twist: Twist, mode: int = NORMAL, reserved: int = 0) -> bytes:
    """The 11 bytes that ask for `twist`."""
    body = _COMMAND.pack(
        HEAD, mode, reserved, milli(twist.forward), milli(twist.left), milli(twist.turn)
    )
    return body + bytes([xor(body), TAIL])


STOP = command(Twist())
"""The chassis port's stop: a frame of zero velocity."""


def status(
    flag_stop: int,
    velocity: tuple[int, int, int],
    accel: tuple[int, int, int],
    gyro: tuple[int, int, int],
    millivolts: int,
) -> bytes:
    """The 24 bytes of a status frame (every number clamped to an int16)."""
    numbers = (*velocity, *accel, *gyro, millivolts)
    body = _STATUS.pack(HEAD, flag_stop, *(max(-INT16 - 1, min(INT16, n)) for n in numbers))
    return body + bytes([xor(body), TAIL])


def _command_of(raw: bytes) -> Command:
    _, mode, reserved, vx, vy, wz = _COMMAND.unpack_from(raw)
    return Command(vx, vy, wz, mode, reserved, raw)


def _status_of(raw: bytes) -> Status:
    _, flag, vx, vy, wz, ax, ay, az, gx, gy, gz, mv = _STATUS.unpack_from(raw)
    return Status(flag, vx, vy, wz, (ax, ay, az), (gx, gy, gz), mv, raw)


F = TypeVar("F", Command, Status)


class _Finder(Generic[F]):
    """Frames of one length found in a byte stream, with a bounded buffer."""

    length = 0

    def __init__(self) -> None:
        self._held = bytearray()

    def _frame(self, raw: bytes) -> F:
        raise NotImplementedError

    @linear
    def feed(self, data: bytes) -> list[F | Junk]:
        """The events `data` completes (a frame cut between calls waits for its end)."""
        held, length = self._held, self.length
        held += data
        out: list[F | Junk] = []
        start = 0  # where the bytes not yet given to an event begin
        at = 0  # where a frame is looked for
        bad: str | None = None  # why the last frame that looked like one was not
        while True:
            at = held.find(HEAD, at)
            if at < 0:
                at = len(held)
                break
            if len(held) - at < length:
                break
            end = at + length
            if held[end - 1] == TAIL and xor(held[at : end - 2]) == held[end - 2]:
                _junk(out, held[start:at], bad)
                out.append(self._frame(bytes(held[at:end])))
                start = at = end
                bad = None
                continue
            if held[end - 1] == TAIL and bad is None:
                bad = f"a frame with a wrong XOR ({held[end - 2]:02X}, expected " + (
                    f"{xor(held[at : end - 2]):02X})"
                )
            at += 1
        _junk(out, held[start:at], bad)
        del held[:at]
        return out

    def flush(self) -> list[Junk]:
        """What is held at the end: a frame cut off."""
        out: list[Junk] = []
        _junk(out, self._held, "a frame cut off" if self._held else None)
        self._held.clear()
        return out


def _junk(out: list[Any], raw: bytes | bytearray, reason: str | None) -> None:
    """`raw` as Junk events of at most MAX_RUN bytes each."""
    for at in range(0, len(raw), MAX_RUN):
        out.append(Junk(bytes(raw[at : at + MAX_RUN]), reason or OUTSIDE))


class CommandDecoder(_Finder[Command]):
    """Host → board: velocity frames, and what is no frame."""

    length = COMMAND_LEN

    def _frame(self, raw: bytes) -> Command:
        return _command_of(raw)


class StatusDecoder(_Finder[Status]):
    """Board → host: status frames, and what is no frame (other boards' extra frames
    among them: a docking car's 8-byte recharge frame, a brushless car's 19-byte
    ultrasonic frame)."""

    length = STATUS_LEN

    def _frame(self, raw: bytes) -> Status:
        return _status_of(raw)


JSON_KEYS = (
    "kind", "forward", "left", "turn", "mode", "reserved", "flag_stop", "acceleration",
    "angular_velocity", "volts", "reason", "raw",
)  # fmt: skip
"""Every key `as_json` writes, in the order a table (CSV) shows them."""


def as_json(event: Event) -> dict[str, object]:
    """An event as `appmode decode --chassis` writes it: SI units, the bytes in hex."""
    raw = event.raw.hex(" ")
    if isinstance(event, Junk):
        return {"kind": "garbage", "reason": event.reason, "raw": raw}
    moving = event.twist
    out: dict[str, object] = {
        "kind": "chassis_command" if isinstance(event, Command) else "chassis_status",
        "forward": moving.forward,
        "left": moving.left,
        "turn": moving.turn,
    }
    if isinstance(event, Command):
        out |= {"mode": event.mode, "reserved": event.reserved}
    else:
        out |= {
            "flag_stop": event.flag_stop,
            "acceleration": [round(a, 4) for a in event.acceleration],
            "angular_velocity": [round(w, 5) for w in event.angular_velocity],
            "volts": event.volts,
        }
    return out | {"raw": raw}
