"""The reference firmware's numbers as its chip holds them: 32-bit floats, and C `int`
conversions (docs/protocol.md §13, §13.1)."""

from __future__ import annotations

import math
import struct


def float32(x: float) -> float:
    """`x` rounded to the nearest 32-bit float (±inf beyond its range), as C stores it."""
    if not math.isfinite(x):
        return x
    try:
        return float(struct.unpack("<f", struct.pack("<f", x))[0])
    except OverflowError:
        return math.copysign(math.inf, x)


def c_int(x: float) -> int:
    """A float converted to a 32-bit `int` as the chip does: truncated, saturated, NaN 0."""
    if math.isnan(x):
        return 0
    if x >= 2**31:
        return 2**31 - 1
    if x <= -(2**31):
        return -(2**31)
    return math.trunc(x)


def times_float32(x: float, factor: float) -> float:
    """`x * factor` with both as float32, as the chip multiplies: the double product of
    two float32 values is exact, so rounding it once gives the float32 product."""
    return float32(float32(x) * float32(factor))
