"""The console's status panel: a view of the session, as styled text fragments (the
APP port's here, the control port's in `control_panel`)."""

from __future__ import annotations

from appmode.console.control_panel import control_body
from appmode.console.panel_parts import (
    GLYPHS,
    WIDTH,
    Fragments,
    columns,
    header,
    hold_mode,
    key_grid,
    link_line,
    telemetry,
)
from appmode.console.waves import waveform_lines
from appmode.host.state import TRACE_SECONDS
from appmode.protocol import params
from appmode.protocol.directions import grid_for, letter_name
from appmode.session.app_session import KEYS_HELP, Session
from appmode.session.base import BaseSession
from appmode.session.control_session import ControlSession


def status_fragments(session: BaseSession, waveforms: bool = False) -> Fragments:
    """The whole panel; the waveforms in place of the key grid if asked."""
    if isinstance(session, ControlSession):
        return header(session, "appmode drive --uart2") + control_body(session)
    assert isinstance(session, Session)
    return header(session, "appmode drive") + _app_body(session, waveforms)


def _app_body(session: Session, waveforms: bool) -> Fragments:
    host = session.host
    now = host.now()
    state = host.state
    out = link_line(host.connected, state.stats, now)
    out += telemetry(state, now)
    out.append(("bold", " page     "))
    out.append(("", f" {session.page_text}   "))
    out.append(("bold", "in force "))
    moving = session.in_force != "Z"
    out.append(("reverse bold" if moving else "", f" {session.in_force_text} "))
    out.append(("", f"   {hold_mode(session.driving)}\n"))
    if state.letters_ignored:
        out.append(("bold", " control  "))
        out.append(("reverse bold fg:ansiyellow", " the car does not follow the letters "))
        out.append(("", "  UART2 may have taken over (§8.3)\n"))

    out.append(("bold", " params   "))
    record = state.params
    if record is None:
        out.append(("", " not read yet (p reads them)\n"))
    else:
        out += columns(
            [f"{p.name} {value}" for p, value in zip(params.PARAMS, record.values, strict=True)]
        )

    if waveforms:
        out.append(("bold", f" last {TRACE_SECONDS:g} s (v: the key grid)\n"))
        out += [("", line + "\n") for line in waveform_lines(state, now, WIDTH)]
        out.append(("fg:ansibrightblack", f" {KEYS_HELP.replace(chr(10), chr(10) + ' ')}\n"))
        return out
    letters = grid_for(session.page)

    def cell(r: int, c: int) -> str:
        letter = letters[r][c]
        return f"{letter} {GLYPHS[r][c]} {letter_name(session.page, letter)}"

    cells = [(r, c) for r in range(3) for c in range(3)]
    lit = next((cell(r, c) for r, c in cells if moving and letters[r][c] == session.in_force), None)
    return out + key_grid(session, cell, lit)


def status_text(session: BaseSession) -> str:
    """The panel as plain text."""
    return "".join(fragment[1] for fragment in status_fragments(session)).rstrip("\n")
