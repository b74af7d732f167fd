"""The console's status panel: a view of the session, as styled text fragments."""

from __future__ import annotations

from typing import TYPE_CHECKING

from prompt_toolkit.formatted_text import StyleAndTextTuples

from appmode.protocol import params
from appmode.protocol.directions import grid_for, letter_name

if TYPE_CHECKING:
    from appmode.console.session import Session

Fragments = StyleAndTextTuples

KEY_GRID = (("q", "w", "e"), ("a", "s", "d"), ("z", "x", "c"))
"""Keys laid out like the phone's 3×3 grid: row 0 is the front."""
ARROWS = {"up": (0, 1), "down": (2, 1), "left": (1, 0), "right": (1, 2)}
"""Arrow keys by grid position."""
GLYPHS = (("↖", "↑", "↗"), ("←", "■", "→"), ("↙", "↓", "↘"))
BAR = 20
KEYS_HELP = (
    "arrows or q w e / a s d / z x c drive (hold) · space stop · i j k page · l latch\n"
    " + - speed · p params · : command line · ? help · Ctrl-C quit"
)


STALE = 0.5
"""Seconds without a record after which the panel shows how long it has been."""


def _size(count: int) -> str:
    return f"{count} B" if count < 1000 else f"{count // 1000} kB"


def _bar(percent: int) -> str:
    """A BAR-wide gauge; a reading outside 0–100 (a garbled or odd board) fills it to
    its end, never beyond."""
    filled = round(min(100, max(0, percent)) / 100 * BAR)
    return "[" + "#" * filled + "." * (BAR - filled) + "]"


def status_fragments(session: Session) -> Fragments:
    """The whole panel."""
    host = session.host
    now = host.now()
    stats = host.state.stats
    out: Fragments = [("bold", " appmode drive  ")]
    if session.simulated:
        out.append(("reverse bold fg:ansiyellow", " SIMULATED BOARD "))
    else:
        out.append(("reverse bold fg:ansigreen", " REAL BOARD "))
    out.append(("", f"  {session.url}\n"))

    if host.connected:
        age = stats.since_last(now)
        if age is None:
            last = "no record yet"
        else:
            last = "records live" if age < STALE else f"last record {age:.1f} s ago"
        stale = age is None or age > 1.0
        recent = stats.recent_errors(now)
        if recent:
            out.append(("reverse bold fg:ansiyellow", f" link DEGRADED: {recent} errors in 5 s "))
        else:
            out.append(("fg:ansired bold" if stale else "fg:ansigreen", " link up"))
        out.append(
            (
                "",
                f"   {stats.rate(now):3.0f} records/s · in {_size(stats.bytes_in)} · "
                f"out {_size(stats.bytes_out)} · errors {stats.errors} · {last}\n",
            )
        )
    else:
        out.append(("reverse bold fg:ansired", " LINK LOST — retrying; keys do nothing "))
        out.append(("", "\n"))

    v, a = host.state.velocity, host.state.attitude
    velocity = "  —" if v is None else f"x {v.x:6d}   y {v.y:6d}   z {v.z:6d}"
    attitude = "  —" if a is None else f"pitch {a.pitch:4d}   roll {a.roll:4d}   yaw {a.yaw:4d}"
    out.append(("bold", " velocity "))
    out.append(("", f" {velocity}\n"))
    out.append(("bold", " attitude "))
    out.append(("", f" {attitude}\n"))
    out.append(("bold", " battery  "))
    if a is None:
        out.append(("", "  —\n"))
    else:
        style = "fg:ansired" if a.battery < 20 else "fg:ansigreen"
        out.append((style, f" {a.battery:3d} % {_bar(a.battery)}\n"))

    mode = (
        "latched"
        if session.driving.latched
        else f"hold (release after {session.driving.first_timeout:g} s, "
        f"then {session.driving.repeat_timeout:g} s)"
    )
    out.append(("bold", " page     "))
    out.append(("", f" {session.page_text}   "))
    out.append(("bold", "in force "))
    moving = session.in_force != "Z"
    out.append(("reverse bold" if moving else "", f" {session.in_force_text} "))
    out.append(("", f"   {mode}\n"))

    out.append(("bold", " params   "))
    record = host.state.params
    if record is None:
        out.append(("", " not read yet (p reads them)\n"))
    else:
        pairs = [f"{p.name} {value}" for p, value in zip(params.PARAMS, record.values, strict=True)]
        for row in range(0, len(pairs), 3):
            prefix = " " if row == 0 else "           "
            out.append(("", prefix + " · ".join(pairs[row : row + 3]) + "\n"))

    out.append(("", "\n"))
    letters = grid_for(session.page)
    for r in range(3):
        out.append(("", "   "))
        for c in range(3):
            letter = letters[r][c]
            style = "reverse bold" if letter == session.in_force and moving else ""
            cell = f"{KEY_GRID[r][c]} {letter} {GLYPHS[r][c]} {letter_name(session.page, letter)}"
            out.append((style, cell.ljust(22)))
        out.append(("", "\n"))
    out.append(("fg:ansibrightblack", f" {KEYS_HELP}\n"))
    return out


def status_text(session: Session) -> str:
    """The panel as plain text."""
    return "".join(fragment[1] for fragment in status_fragments(session)).rstrip("\n")
