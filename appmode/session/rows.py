"""What a session shows, for any view: rows of a label and spans of text, each span with
a tone (what it means: a value in force, a warning, a stale reading), never a style.

The terminal panel renders the rows as styled text; another view maps the same tones to
its own look. The session decides what to say and how fresh it is; a view decides how
it looks.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from appmode.host.app.state import HostState
from appmode.host.stats import LinkStats
from appmode.session import instruments
from appmode.session.hold import HoldToDrive
from appmode.session.instruments import STALE, link
from appmode.text import counted

Tone = Literal["", "label", "on", "ok", "warn", "alert", "late", "low", "dim"]
"""What a span means: plain, a label inside a row, in force (a car moving), fine, a
warning, an alarm, a link that is late, a low battery, old or secondary."""
Span = tuple[Tone, str]

GLYPHS = (("↖", "↑", "↗"), ("←", "■", "→"), ("↙", "↓", "↘"))
"""The 3×3 grid's arrows: row 0 is the front."""
SILENT_HINT = "is the car on (and paired)? appmode doctor finds its port and baud rate"
BAR = 20
WIDTH = 80
"""Columns every row fits in."""


@dataclass(frozen=True, slots=True)
class Row:
    """One line of status: a label (empty: none), then its spans; `pairs` are
    `name value` texts a view lays out in columns after the spans."""

    label: str
    spans: tuple[Span, ...] = ()
    pairs: tuple[str, ...] = ()

    @property
    def text(self) -> str:
        return "".join(text for _, text in self.spans)


def _size(count: int) -> str:
    return f"{count} B" if count < 1000 else f"{count // 1000} kB"


def bar(percent: int) -> str:
    """A BAR-wide gauge; a reading outside 0–100 (a garbled or odd board) fills it to
    its end, never beyond."""
    filled = round(min(100, max(0, percent)) / 100 * BAR)
    return "[" + "#" * filled + "." * (BAR - filled) + "]"


def link_spans(
    connected: bool,
    stats: LinkStats,
    now: float,
    noun: str = "records",
    brief: bool = False,
    latency: float | None = None,
) -> tuple[Span, ...] | None:
    """Whether the link is up: counters (bytes unless `brief`), errors, how fresh what it
    brings is, the network's latency to a shared car; None while the port is open and
    nothing has come."""
    state = link(connected, stats, now, latency)
    if state.state == "lost":
        return (("alert", " LINK LOST — retrying; keys do nothing "),)
    if state.age is None:
        return None
    age = state.age
    last = f"{noun} live" if age < STALE else f"last {noun[:-1]} {age:.1f} s ago"
    if state.state == "degraded":
        first: Span = ("warn", f" link DEGRADED: {counted(state.recent_errors, 'error')} in 5 s ")
    else:
        first = ("late" if state.state == "late" else "ok", " link up")
    sizes = "" if brief else f"in {_size(state.bytes_in)} · out {_size(state.bytes_out)} · "
    rate = f"  {state.rate:3.0f} {noun}/s · {sizes}errors {state.errors} · {last}"
    if state.latency is not None:
        rate += f" · latency {state.latency:.1f} ms"
    return first, ("", rate)


UNSENT = " NOT STOPPED: the link is down and the car may still be moving (no stop can reach it) "
"""What a view shows while motion is in force and the link is down: it never shows a stop
that was not sent."""


def unsent_row() -> Row:
    """The row that says the car's last command was motion and no stop can be sent."""
    return Row("", (("alert", UNSENT),))


def link_rows(
    connected: bool,
    stats: LinkStats,
    now: float,
    noun: str = "records",
    hint: str = SILENT_HINT,
    label: str = "",
    brief: bool = False,
    latency: float | None = None,
) -> list[Row]:
    """The link row (under `label`); a port open with nothing received says so, and
    after SILENT what to check (it is not known to be up)."""
    spans = link_spans(connected, stats, now, noun, brief, latency)
    if spans is not None:
        return [Row(label, spans)]
    if link(connected, stats, now).state == "opening":
        return [Row(label, (("", " port open, nothing received "),))]
    return [
        Row(label, (("alert", " port open, nothing received "),)),
        Row("", (("", f"  {hint}"),)),
    ]


def reading(label: str, text: str, age: float | None) -> Row:
    """A row of values; dimmed, with their age, once they are not fresh (a silent or
    lost link must not show a car that looks as if it were moving)."""
    if age is None or age <= STALE:
        return Row(label, (("", f" {text}"),))
    return Row(label, (("dim", f" {text}   ({age:.1f} s ago)"),))


def telemetry(state: HostState, now: float) -> list[Row]:
    """The A and B records: velocity, attitude, battery (as `instruments.telemetry` reads
    them)."""
    t = instruments.telemetry(state, now)
    velocity = "  —" if t.motion is None else "   ".join(f"{n} {v:6d}" for n, v in t.motion)
    if t.b is not None:  # a profile's own B record, by its fields' labels
        attitude = "   ".join(f"{n} {v:6d}" for n, v in t.b)
    elif t.pitch is None:
        attitude = "  —"
    else:
        attitude = f"pitch {t.pitch:4d}   roll {t.roll:4d}   yaw {t.yaw:4d}"
    rows = [
        reading("velocity", velocity, t.motion_age),
        reading("attitude", attitude, t.attitude_age),
    ]
    if t.battery is None:
        return [*rows, Row("battery", (("", "  —"),))]
    old = (t.battery_age or 0.0) > STALE
    tone: Tone = "dim" if old else "low" if t.battery < 20 else "ok"
    return [*rows, Row("battery", ((tone, f" {t.battery:3d} % {bar(t.battery)}"),))]


def hold_mode(driving: HoldToDrive) -> str:
    if driving.latched:
        return "latched"
    return f"hold {driving.first_timeout:g}/{driving.repeat_timeout:g} s"
