"""What both panels are made of: the header, the link line, the APP port's telemetry,
columns of values and the key grid, as styled text fragments."""

from __future__ import annotations

from collections.abc import Callable

from prompt_toolkit.formatted_text import StyleAndTextTuples

from appmode.host.state import HostState, LinkStats
from appmode.protocol import app
from appmode.session.base import BaseSession
from appmode.session.hold import HoldToDrive
from appmode.text import counted

Fragments = StyleAndTextTuples

KEY_GRID = (("q", "w", "e"), ("a", "s", "d"), ("z", "x", "c"))
"""Keys laid out like the phone's 3×3 grid: row 0 is the front."""
ARROWS = {"up": (0, 1), "down": (2, 1), "left": (1, 0), "right": (1, 2)}
"""Arrow keys by grid position."""
GLYPHS = (("↖", "↑", "↗"), ("←", "■", "→"), ("↙", "↓", "↘"))
BAR = 20
WIDTH = 80
"""Columns every panel line fits in."""


STALE = 0.5
"""Seconds without a record after which the panel shows how long it has been."""
SILENT = 2.0
"""Seconds after opening with nothing received after which the panel says what to check."""
SILENT_HINT = "is the car on (and paired)? appmode doctor finds its port and baud rate"


def _size(count: int) -> str:
    return f"{count} B" if count < 1000 else f"{count // 1000} kB"


def _bar(percent: int) -> str:
    """A BAR-wide gauge; a reading outside 0–100 (a garbled or odd board) fills it to
    its end, never beyond."""
    filled = round(min(100, max(0, percent)) / 100 * BAR)
    return "[" + "#" * filled + "." * (BAR - filled) + "]"


def header(session: BaseSession, title: str) -> Fragments:
    """The title, whether the board is simulated, and its URL (cut to fit WIDTH)."""
    badge = " SIMULATED BOARD " if session.simulated else " REAL BOARD "
    out: Fragments = [("bold", f" {title}  ")]
    out.append(
        ("reverse bold fg:ansiyellow" if session.simulated else "reverse bold fg:ansigreen", badge)
    )
    room = WIDTH - len(title) - len(badge) - 5
    url = session.url if len(session.url) <= room else session.url[: room - 1] + "…"
    out.append(("", f"  {url}\n"))
    return out


def link_line(
    connected: bool,
    stats: LinkStats,
    now: float,
    noun: str = "records",
    hint: str = SILENT_HINT,
    brief: bool = False,
) -> Fragments:
    """Whether the link is up: counters (bytes unless `brief`), errors, how fresh what it
    brings is."""
    age = stats.since_last(now)
    if not connected:
        return [("reverse bold fg:ansired", " LINK LOST — retrying; keys do nothing "), ("", "\n")]
    if age is None:  # open, but nothing has come: it is not known to be up
        waiting = now > SILENT
        return [
            ("reverse bold fg:ansired" if waiting else "", " port open, nothing received "),
            ("", f"\n  {hint}\n" if waiting else "\n"),
        ]
    last = f"{noun} live" if age < STALE else f"last {noun[:-1]} {age:.1f} s ago"
    recent = stats.recent_errors(now)
    if recent:
        out: Fragments = [
            ("reverse bold fg:ansiyellow", f" link DEGRADED: {counted(recent, 'error')} in 5 s ")
        ]
    else:
        out = [("fg:ansired bold" if age > 1.0 else "fg:ansigreen", " link up")]
    sizes = "" if brief else f"in {_size(stats.bytes_in)} · out {_size(stats.bytes_out)} · "
    out.append(("", f"  {stats.rate(now):3.0f} {noun}/s · {sizes}errors {stats.errors} · {last}\n"))
    return out


def telemetry(state: HostState, now: float) -> Fragments:
    """The A and B records: velocity, attitude, battery."""
    v, a = state.velocity, state.attitude
    if v is None:
        velocity = "  —"
    else:
        values, labels = app.record_fields(v)[1], state.layout.labels
        velocity = "   ".join(f"{labels[i]} {values[i]:6d}" for i in state.layout.motion)
    attitude = "  —" if a is None else f"pitch {a.pitch:4d}   roll {a.roll:4d}   yaw {a.yaw:4d}"
    out = reading(" velocity ", velocity, state.velocities.age(now))
    out += reading(" attitude ", attitude, state.attitudes.age(now))
    out.append(("bold", " battery  "))
    if a is None:
        out.append(("", "  —\n"))
    else:
        old = (state.attitudes.age(now) or 0.0) > STALE
        style = "fg:ansibrightblack" if old else "fg:ansired" if a.battery < 20 else "fg:ansigreen"
        out.append((style, f" {a.battery:3d} % {_bar(a.battery)}\n"))
    return out


def hold_mode(driving: HoldToDrive) -> str:
    if driving.latched:
        return "latched"
    return f"hold {driving.first_timeout:g}/{driving.repeat_timeout:g} s"


def columns(pairs: list[str], per_row: int = 3) -> Fragments:
    """`name value` pairs, `per_row` to a line, under a 10-column label."""
    out: Fragments = []
    for row in range(0, len(pairs), per_row):
        prefix = " " if row == 0 else "           "
        out.append(("", prefix + " · ".join(pairs[row : row + per_row]) + "\n"))
    return out


def key_grid(session: BaseSession, name: Callable[[int, int], str], lit: str | None) -> Fragments:
    """The 3×3 grid: each key, its glyph and what it does; `lit` the cell in force."""
    out: Fragments = [("", "\n")]
    for r in range(3):
        out.append(("", "   "))
        for c in range(3):
            what = name(r, c)
            style = "reverse bold" if what == lit else ""
            out.append((style, f"{KEY_GRID[r][c]} {what}".ljust(22)))
        out.append(("", "\n"))
    out.append(("fg:ansibrightblack", f" {session.keys_help.replace(chr(10), chr(10) + ' ')}\n"))
    return out


def reading(label: str, text: str, age: float | None) -> Fragments:
    """A line of values; greyed, with their age, once they are not fresh (a silent or
    lost link must not show a car that looks as if it were moving)."""
    if age is None or age <= STALE:
        return [("bold", label), ("", f" {text}\n")]
    return [("bold", label), ("fg:ansibrightblack", f" {text}   ({age:.1f} s ago)\n")]
