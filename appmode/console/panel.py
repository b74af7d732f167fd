"""The console's status panel: what the session shows (its status rows and key grid),
as styled text fragments; with waveforms in place of the grid if asked."""

from __future__ import annotations

from appmode.console.panel_parts import Fragments, header, key_grid, keys_help, rows
from appmode.console.waves import waveform_lines
from appmode.host.app.state import TRACE_SECONDS
from appmode.session.base import BaseSession
from appmode.session.rows import WIDTH


def status_fragments(session: BaseSession, waveforms: bool = False) -> Fragments:
    """The whole panel; the waveforms in place of the key grid if asked (and drawn)."""
    out = header(session) + rows(session.status_rows())
    state = session.telemetry_state()
    if not waveforms or state is None:
        return out + key_grid(session)
    out.append(("bold", f" last {TRACE_SECONDS:g} s (v: the key grid)\n"))
    out += [("", line + "\n") for line in waveform_lines(state, session.now(), WIDTH)]
    return out + keys_help(session)


def status_text(session: BaseSession) -> str:
    """The panel's status as plain text, for a script: its header and rows (no key
    grid and no keys: a script types no keys)."""
    out = header(session) + rows(session.status_rows())
    return "".join(fragment[1] for fragment in out).rstrip("\n")
