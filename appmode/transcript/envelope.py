"""A series reduced, as it streams, to what a picture can show: per time bin its first,
lowest, highest and last value with their times, in at most BINS bins whatever its
length. The bins start narrow; when a time falls past the last one, every bin's width
doubles and each pair of neighbours merges, so a series is read once, in time linear in
its length and memory bounded by BINS (`plot` of a 200 MB transcript holds what a 2 MB
one does)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Generic, NamedTuple, TypeVar

BINS = 2048
"""Bins a series keeps: more than the pixel columns of a plot (1,210 at 11 in, 110 dpi)."""
FIRST_WIDTH = 0.001
"""Seconds a bin spans at first: a short transcript keeps every record as it is."""

T = TypeVar("T")


class TimeBins(Generic[T]):
    """Values put at times, at most `size` bins of them, a bin's values `merge`d."""

    def __init__(self, merge: Callable[[T, T], T], size: int = BINS) -> None:
        self._merge = merge
        self._size = size
        self._origin: float | None = None
        self._width = FIRST_WIDTH
        self._bins: list[T | None] = [None] * size

    def put(self, t: float, value: T) -> None:
        if self._origin is None:
            self._origin = t
        at = max(0, int((t - self._origin) / self._width))
        while at >= self._size:
            self._widen()
            at = int((t - self._origin) / self._width)
        old = self._bins[at]
        self._bins[at] = value if old is None else self._merge(old, value)

    def _widen(self) -> None:
        """Every bin twice as wide: each pair of neighbours merged into one."""
        bins, merge = self._bins, self._merge
        merged: list[T | None] = []
        for i in range(0, self._size, 2):
            first, second = bins[i], bins[i + 1] if i + 1 < self._size else None
            merged.append(
                first if second is None else second if first is None else merge(first, second)
            )
        self._bins = merged + [None] * (self._size - len(merged))
        self._width *= 2

    def kept(self) -> list[T]:
        """The bins that hold something, in time order."""
        return [value for value in self._bins if value is not None]


class Extremes(NamedTuple):
    """A bin's first, lowest, highest and last value, each with its time."""

    first: tuple[float, float]
    low: tuple[float, float]
    high: tuple[float, float]
    last: tuple[float, float]


def _joined(a: Extremes, b: Extremes) -> Extremes:
    """Two bins as one (`a` the earlier)."""
    low = a.low if a.low[1] <= b.low[1] else b.low
    high = a.high if a.high[1] >= b.high[1] else b.high
    return Extremes(a.first, low, high, b.last)


class Envelope:
    """One series of numbers over time, reduced to its first, last and extremes per
    bin: where it starts and ends, every step between bins, and every peak, are drawn
    as they were."""

    def __init__(self, size: int = BINS) -> None:
        self._bins: TimeBins[Extremes] = TimeBins(_joined, size)
        self.count = 0

    def add(self, t: float, value: float) -> None:
        point = (t, value)
        self._bins.put(t, Extremes(point, point, point, point))
        self.count += 1

    def points(self) -> tuple[list[float], list[float]]:
        """Times and values to draw, in time order (a point once, however many roles it
        has in its bin)."""
        times: list[float] = []
        values: list[float] = []
        for bin_ in self._bins.kept():
            for t, value in sorted(set(bin_)):
                times.append(t)
                values.append(value)
        return times, values


MARKS = 512
"""Marks kept: a dotted line each on a plot 1,210 pixels wide."""


class Marks:
    """Times with a text (the commands sent), the first of each bin kept."""

    def __init__(self, size: int = MARKS) -> None:
        self._bins: TimeBins[tuple[float, str]] = TimeBins(lambda first, _: first, size)

    def add(self, t: float, text: str) -> None:
        self._bins.put(t, (t, text))

    def kept(self) -> list[tuple[float, str]]:
        return self._bins.kept()
