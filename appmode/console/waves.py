"""Waveforms, as the phone app draws them: the last seconds of each telemetry field as one
line of block characters, scaled to its own range."""

from __future__ import annotations

from appmode.host.app.state import TRACE_SECONDS, HostState, Trace

LEVELS = "▁▂▃▄▅▆▇█"


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
    """One line a field: label, waveform, and the range it spans; the A record's motion
    fields, then the B record's, as the board's layout names them."""
    layout = state.layout
    series: list[tuple[str, Trace, int]] = [
        (f"v{layout.labels[i]}" if layout.signed else layout.labels[i], state.velocities, i)
        for i in layout.motion
    ]
    series += [(field.label, state.attitudes, i) for i, field in enumerate(layout.b_fields)]
    lines = []
    for label, trace, field in series:
        points = [(t, event.values[field]) for t, event in trace.points]
        values = [v for _, v in points]
        span = f"{min(values)}…{max(values)}" if values else "—"
        lines.append(f" {label:<8}{sparkline(points, now, width - 24)}  {span:>13}")
    return lines
