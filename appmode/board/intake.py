"""How the reference firmware reads the APP port, byte by byte (docs/protocol.md §13).

`FirmwareIntake.feed` returns, in order, the direction event of each byte that steers
(§2.1's table) and a `Frame` for each frame collected from `{` to `}`. Frames are read
as the firmware reads them: position 3 `P` reads, `W` saves, `#` in position 1 makes the
frame ignored, else position 1 is a parameter index and the value is the float32 sum of
(byte − 0x30) × 10^k over the bytes from position 3 to the one before `}`, summed from
the last (§13.1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from appmode.board.chip import float32
from appmode.protocol import app, app_decoders, control

INT_PARAMS = (0, 1)
"""max_speed and max_position, which the firmware keeps as `int` (the others as floats)."""
MAX_KEPT = 4096
"""Longest frame kept (the real buffer overflows; a longer frame is ignored here)."""


@dataclass(frozen=True, slots=True)
class Frame:
    """One collected frame and what the firmware makes of it."""

    raw: bytes
    action: str  # "read", "save", "set" or "ignored"
    index: int = -1
    value: float = 0.0
    reason: str = ""


@dataclass(frozen=True, slots=True)
class Steer:
    """One byte's direction event (§2.1); `framed` when the byte is part of a frame."""

    event: app.ByteEvent
    framed: bool


_STEER = tuple(
    tuple(Steer(event, framed) for event in app_decoders.single_byte_events())
    for framed in (False, True)
)


def frame_value(digits: bytes) -> float:
    """Σ (byte − 0x30) × 10^k, k = 0 at the last byte, summed from the last byte to the
    first: each term in double, the sum rounded to float32 at every step (§13.1)."""
    total = 0.0
    for k, byte in enumerate(reversed(digits)):
        total = float32(total + (byte - 0x30) * (10.0**k if k < 309 else math.inf))
    return total


def parse_frame(raw: bytes) -> Frame:
    """What the firmware does with one frame, `{` to `}` included."""
    if len(raw) > 4 and raw[3] in b"PW":
        return Frame(raw, "read" if raw[3] == 0x50 else "save")
    index = raw[1] - 0x30 if len(raw) > 2 else -1
    if len(raw) > 2 and raw[1] == 0x23:
        return Frame(raw, "ignored", reason="'#' in position 1")
    if not 0 <= index <= 9:
        return Frame(raw, "ignored", reason="no parameter index in position 1")
    return Frame(raw, "set", index, frame_value(raw[3:-1]))


class FirmwareIntake:
    """host→board bytes → direction events and collected frames, per the switches."""

    def __init__(self, steer_in_frames: bool, frame_restarts: bool) -> None:
        self.steer_in_frames = steer_in_frames
        self.frame_restarts = frame_restarts
        self._frame: bytearray | None = None
        self._length = 0  # bytes of the open frame, including any not kept

    def feed(self, data: bytes) -> list[Steer | Frame]:
        out: list[Steer | Frame] = []
        loose, framed = _STEER
        for byte in data:
            frame = self._frame
            if frame is None or (byte == app.LBRACE and self.frame_restarts):
                if byte == app.LBRACE:
                    self._frame, self._length = bytearray(b"{"), 1
                    if self.steer_in_frames:
                        out.append(framed[byte])
                else:
                    out.append(loose[byte])
                continue
            if self.steer_in_frames:
                out.append(framed[byte])
            self._length += 1
            if len(frame) < MAX_KEPT:
                frame.append(byte)
            if byte == app.RBRACE:
                self._frame = None
                if self._length > MAX_KEPT:
                    reason = f"a frame of {self._length:,} bytes is more than the board keeps"
                    out.append(Frame(bytes(frame[:64]), "ignored", reason=reason))
                else:
                    out.append(parse_frame(bytes(frame)))
        return out


class ControlIntake:
    """UART2 as the reference loop reads it (§13.1, §13.3): every byte received, a
    frame's own included, goes through the header detector; when no frame is being
    collected, the byte after the last two received `FF FE` starts one, and it and the
    next 7 are the frame whatever they hold. `feed` returns the frames completed, header
    included; `receiving` says whether one is under way (its first byte came)."""

    def __init__(self) -> None:
        self._frame = bytearray()
        self._last = (-1, -1)  # the last two bytes received, in order

    @property
    def receiving(self) -> bool:
        return bool(self._frame)

    def feed(self, data: bytes) -> list[bytes]:
        out: list[bytes] = []
        frame, size = self._frame, control.FRAME - len(control.HEADER)
        first, second = control.HEADER
        before, last = self._last
        for byte in data:
            if frame or (before == first and last == second):
                frame.append(byte)
                if len(frame) == size:
                    out.append(control.HEADER + frame)
                    frame.clear()
            before, last = last, byte
        self._last = (before, last)
        return out
