"""The console's status panel: a view of the session, as styled text fragments."""

from __future__ import annotations

from typing import TYPE_CHECKING

from prompt_toolkit.formatted_text import StyleAndTextTuples

from appmode.console.session import KEYS_HELP
from appmode.console.waves import waveform_lines
from appmode.host.state import TRACE_SECONDS
from appmode.protocol import app, params
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
WIDTH = 80
"""Columns every panel line fits in."""


STALE = 0.5
"""Seconds without a record after which the panel shows how long it has been."""
SILENT = 2.0
"""Seconds after opening with nothing received after which the panel says what to check."""
SILENT_HINT = "check the baud rate (9600), that the car is on, and Bluetooth is paired"


def _size(count: int) -> str:
    return f"{count} B" if count < 1000 else f"{count // 1000} kB"


def _bar(percent: int) -> str:
    """A BAR-wide gauge; a reading outside 0–100 (a garbled or odd board) fills it to
    its end, never beyond."""
    filled = round(min(100, max(0, percent)) / 100 * BAR)
    return "[" + "#" * filled + "." * (BAR - filled) + "]"


def status_fragments(session: Session, waveforms: bool = False) -> Fragments:
    """The whole panel; the waveforms in place of the key grid if asked."""
    host = session.host
    now = host.now()
    stats = host.state.stats
    out: Fragments = [("bold", " appmode drive  ")]
    if session.simulated:
        out.append(("reverse bold fg:ansiyellow", " SIMULATED BOARD "))
    else:
        out.append(("reverse bold fg:ansigreen", " REAL BOARD "))
    out.append(("", f"  {session.url}\n"))

    age = stats.since_last(now)
    if not host.connected:
        out.append(("reverse bold fg:ansired", " LINK LOST — retrying; keys do nothing "))
        out.append(("", "\n"))
    elif age is None:  # open, but nothing has come: it is not known to be up
        waiting = now > SILENT
        out.append(("reverse bold fg:ansired" if waiting else "", " port open, nothing received "))
        out.append(("", f"  {SILENT_HINT if waiting else ''}\n"))
    else:
        last = "records live" if age < STALE else f"last record {age:.1f} s ago"
        recent = stats.recent_errors(now)
        if recent:
            out.append(("reverse bold fg:ansiyellow", f" link DEGRADED: {recent} errors in 5 s "))
        else:
            out.append(("fg:ansired bold" if age > 1.0 else "fg:ansigreen", " link up"))
        out.append(
            (
                "",
                f"  {stats.rate(now):3.0f} records/s · in {_size(stats.bytes_in)} · "
                f"out {_size(stats.bytes_out)} · errors {stats.errors} · {last}\n",
            )
        )

    state = host.state
    v, a = state.velocity, state.attitude
    if v is None:
        velocity = "  —"
    else:
        values, labels = app.record_fields(v)[1], state.layout.labels
        velocity = "   ".join(f"{labels[i]} {values[i]:6d}" for i in state.layout.motion)
    attitude = "  —" if a is None else f"pitch {a.pitch:4d}   roll {a.roll:4d}   yaw {a.yaw:4d}"
    out += _reading(" velocity ", velocity, state.velocities.age(now))
    out += _reading(" attitude ", attitude, state.attitudes.age(now))
    out.append(("bold", " battery  "))
    if a is None:
        out.append(("", "  —\n"))
    else:
        old = (state.attitudes.age(now) or 0.0) > STALE
        style = "fg:ansibrightblack" if old else "fg:ansired" if a.battery < 20 else "fg:ansigreen"
        out.append((style, f" {a.battery:3d} % {_bar(a.battery)}\n"))

    driving = session.driving
    mode = (
        "latched"
        if driving.latched
        else f"hold {driving.first_timeout:g}/{driving.repeat_timeout:g} s"
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

    if waveforms:
        out.append(("bold", f" last {TRACE_SECONDS:g} s (v: the key grid)\n"))
        out += [("", line + "\n") for line in waveform_lines(state, now, WIDTH)]
        out.append(("fg:ansibrightblack", f" {KEYS_HELP.replace(chr(10), chr(10) + ' ')}\n"))
        return out
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
    out.append(("fg:ansibrightblack", f" {KEYS_HELP.replace(chr(10), chr(10) + ' ')}\n"))
    return out


def _reading(label: str, text: str, age: float | None) -> Fragments:
    """A line of values; greyed, with their age, once they are not fresh (a silent or
    lost link must not show a car that looks as if it were moving)."""
    if age is None or age <= STALE:
        return [("bold", label), ("", f" {text}\n")]
    return [("bold", label), ("fg:ansibrightblack", f" {text}   ({age:.1f} s ago)\n")]


def status_text(session: Session) -> str:
    """The panel as plain text."""
    return "".join(fragment[1] for fragment in status_fragments(session)).rstrip("\n")
