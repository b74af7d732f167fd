"""The control-port console's panel: who drives, the frame in force, the encoder report
(target and actual per wheel), the ten settings, and the APP port's records when the
session holds both ports."""

from __future__ import annotations

from appmode.console.panel_parts import (
    GLYPHS,
    WIDTH,
    Fragments,
    columns,
    hold_mode,
    key_grid,
    link_line,
    reading,
    telemetry,
)
from appmode.protocol import settings
from appmode.protocol.control_view import describe
from appmode.protocol.directions import STOP_LETTER
from appmode.session.control_session import STOP, ControlSession

SILENT_HINT = "check the wiring and that the car is on; appmode doctor finds its port"


def control_body(session: ControlSession) -> Fragments:
    host = session.host
    state = host.state
    now = host.now()
    out = link_line(host.connected, state.stats, now, "messages", SILENT_HINT)

    out.append(("bold", " control  "))
    if state.took_over_at is not None:
        out.append(("reverse bold", " UART2 "))
        out.append(("", f" drives: this session's frames since {state.took_over_at:.2f} s"))
    else:
        out.append(("", f" APP port, until UART2 receives {state.takeover_byte} bytes"))
    drive = session.drive
    out.append(("", f" · drive {'? (reading)' if drive is None else drive.cli_name}\n"))

    start = len(out)
    out.append(("bold", " in force "))
    if session.rotation is not None:
        left = state.values.get("pending_angle")
        to_go = "" if left is None else f", {left / 10:g}° to go"
        out.append(("reverse bold", f" turning {session.rotation[1]:g}°{to_go} "))
    elif session.in_force != STOP:
        out.append(("reverse bold", f" {session.in_force} "))
    elif state.in_force is not None:
        out.append(("reverse bold", f" {describe(state.in_force)} "))
    else:
        out.append(("", " stopped"))
    keys = f"speed {session.speed} · r/R {session.angle:g}° · {hold_mode(session.driving)}"
    shown = sum(len(text) for _, text, *_ in out[start:])
    room = WIDTH - shown - 3
    out.append(("", f"   {keys}\n" if len(keys) <= room else f"\n{' ' * 10}{keys}\n"))

    report = state.report
    if report is None:
        wheels = "  — (the encoder report is off, or none came yet)"
    else:
        pairs = zip(report.targets, report.actuals, strict=True)
        letters = settings.WHEELS[: len(report.targets)]
        wheels = "  ".join(f"{w.upper()} {t}/{a}" for w, (t, a) in zip(letters, pairs, strict=True))
        wheels += "  target/actual"
    age = None if state.report_at is None else now - state.report_at
    out += reading(" wheels   ", wheels, age)

    out.append(("bold", " settings "))
    if not any(s.name in state.values for s in settings.SETTINGS):
        out.append(("", " not read yet (p reads them)\n"))
    else:
        out += columns([f"{s.name} {state.values.get(s.name, '?')}" for s in settings.SETTINGS])

    if session.app is not None:
        app = session.app
        out.append(("bold", " APP port "))
        out += link_line(app.connected, app.state.stats, app.now(), brief=True)
        out += telemetry(app.state, app.now())

    def cell(r: int, c: int) -> str:
        name = session.grid_key(r, c)
        return f"{GLYPHS[r][c]} {'stop' if name == STOP_LETTER else name}"

    lit = None
    if session.in_force != STOP and session.rotation is None:
        cells = [(r, c) for r in range(3) for c in range(3)]
        lit = next(
            (cell(r, c) for r, c in cells if session.grid_key(r, c) == session.in_force), None
        )
    return out + key_grid(session, cell, lit)
