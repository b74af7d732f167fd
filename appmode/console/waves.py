"""Waveforms, as the phone app draws them: the last seconds of each telemetry field as one
line of block characters, scaled to its own range."""

from __future__ import annotations

from appmode.host.state import TRACE_SECONDS, HostState, Trace

LEVELS = "▁▂▃▄▅▆▇█"
SERIES: tuple[tuple[str, str, str], ...] = (
    ("vx", "velocities", "x"),
    ("vy", "velocities", "y"),
    ("vz", "velocities", "z"),
    ("pitch", "attitudes", "pitch"),
    ("roll", "attitudes", "roll"),
    ("yaw", "attitudes", "yaw"),
    ("battery", "attitudes", "battery"),
)
"""(label, HostState trace, record field) for each line."""


def sparkline(points: list[tuple[float, int]], now: float, width: int) -> str:
    """The samples of the last TRACE_SECONDS in `width` columns (the newest on the right),
    each column the last sample in its time, blank before the first."""
    if width <= 0:
        return ""
    start = now - TRACE_SECONDS
    columns: list[int | None] = [None] * width
    for t, value in points:
        column = min(width - 1, int((t - start) / TRACE_SECONDS * width))
        if column >= 0:
            columns[column] = value
    last: int | None = None
    for i, sample in enumerate(columns):  # a column with no sample holds the one before
        if sample is None:
            columns[i] = last
        last = columns[i]
    present = [v for v in columns if v is not None]
    if not present:
        return " " * width
    low, high = min(present), max(present)
    top = len(LEVELS) - 1
    return "".join(
        " "
        if v is None
        else LEVELS[top // 2 if high == low else round((v - low) / (high - low) * top)]
        for v in columns
    )


def waveform_lines(state: HostState, now: float, width: int) -> list[str]:
    """One line per SERIES: label, waveform, and the range it spans."""
    lines = []
    for label, trace_name, field in SERIES:
        trace: Trace = getattr(state, trace_name)
        points = [(t, int(getattr(event, field))) for t, event in trace.points]
        values = [v for _, v in points]
        span = f"{min(values)}…{max(values)}" if values else "—"
        lines.append(f" {label:<8}{sparkline(points, now, width - 24)}  {span:>13}")
    return lines
