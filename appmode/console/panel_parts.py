"""What the terminal panel is made of: the header, a session's status rows as styled
text, and the key grid. Tones (what a span means) become terminal styles here."""

from __future__ import annotations

from prompt_toolkit.formatted_text import StyleAndTextTuples

from appmode.session.base import BaseSession
from appmode.session.rows import WIDTH, Row, Tone

Fragments = StyleAndTextTuples

KEY_GRID = (("q", "w", "e"), ("a", "s", "d"), ("z", "x", "c"))
"""Keys laid out like the phone's 3×3 grid: row 0 is the front."""
ARROWS = {"up": (0, 1), "down": (2, 1), "left": (1, 0), "right": (1, 2)}
"""Arrow keys by grid position."""
STYLES: dict[Tone, str] = {
    "": "",
    "label": "bold",
    "on": "reverse bold",
    "ok": "fg:ansigreen",
    "warn": "reverse bold fg:ansiyellow",
    "alert": "reverse bold fg:ansired",
    "late": "fg:ansired bold",
    "low": "fg:ansired",
    "dim": "fg:ansibrightblack",
}
"""How the terminal shows each tone."""
PER_ROW = 3
"""`name value` pairs on one line."""
LABEL = 9
"""Columns of a row's label."""


def header(session: BaseSession) -> Fragments:
    """The title, whether the board is simulated, and its URL (cut to fit WIDTH)."""
    title = session.title
    badge = " SIMULATED BOARD " if session.simulated else " REAL BOARD "
    out: Fragments = [("bold", f" {title}  ")]
    out.append(
        ("reverse bold fg:ansiyellow" if session.simulated else "reverse bold fg:ansigreen", badge)
    )
    room = WIDTH - len(title) - len(badge) - 5
    url = session.url if len(session.url) <= room else session.url[: room - 1] + "…"
    out.append(("", f"  {url}\n"))
    return out


def rows(status: list[Row]) -> Fragments:
    """Status rows: a bold label, the spans in their tones, pairs in columns."""
    out: Fragments = []
    for row in status:
        if row.label:
            out.append(("bold", f" {row.label:<{LABEL}}"))
        out += [(STYLES[tone], text) for tone, text in row.spans]
        for start in range(0, len(row.pairs), PER_ROW):
            prefix = " " if start == 0 else " " * (LABEL + 2)
            out.append(("", prefix + " · ".join(row.pairs[start : start + PER_ROW]) + "\n"))
        if not row.pairs:
            out.append(("", "\n"))
    return out


def key_grid(session: BaseSession) -> Fragments:
    """The 3×3 grid: each key, its glyph and what it does; the cell in force lit."""
    cells, lit = session.grid_cells(), session.lit_cell()
    out: Fragments = [("", "\n")]
    for r in range(3):
        out.append(("", "   "))
        for c in range(3):
            style = "reverse bold" if (r, c) == lit else ""
            out.append((style, f"{KEY_GRID[r][c]} {cells[r][c]}".ljust(22)))
        out.append(("", "\n"))
    return out + keys_help(session)


def keys_help(session: BaseSession) -> Fragments:
    return [("fg:ansibrightblack", f" {session.keys_help.replace(chr(10), chr(10) + ' ')}\n")]
