"""What the control port's session shows: who drives, the frame in force, the encoder
report (target and actual per wheel), the ten settings, and the APP port's records when
the session holds both ports."""

from __future__ import annotations

from typing import TYPE_CHECKING

from appmode.protocol import settings
from appmode.protocol.control_view import describe
from appmode.protocol.directions import PAGE_LETTERS, letter_name
from appmode.session import instruments
from appmode.session.instruments import Instruments, Value, Wheel
from appmode.session.status import (
    GLYPHS,
    WIDTH,
    Row,
    Span,
    hold_mode,
    link_rows,
    reading,
    telemetry,
    unsent_row,
)

if TYPE_CHECKING:
    from appmode.session.control_session import ControlSession

SILENT_HINT = "check the wiring and that the car is on; appmode doctor finds its port"
STOP = "stop"
"""What is in force when no motion is."""


def control_rows(session: ControlSession) -> list[Row]:
    host = session.host
    state = host.state
    now = host.now()
    rows = link_rows(host.connected, state.stats, now, "messages", SILENT_HINT)

    drive = session.drive
    by_drive: Span = ("", f" · drive {'? (reading)' if drive is None else drive.cli_name}")
    if state.took_over_at is not None:
        since = f" drives: this session's frames since {state.took_over_at:.2f} s"
        rows.append(Row("control", (("on", " UART2 "), ("", since), by_drive)))
    else:
        until = f" APP port, until UART2 receives {state.takeover_byte} bytes"
        rows.append(Row("control", (("", until), by_drive)))

    rows += _in_force(session)

    report = state.report
    if report is None:
        wheels = "  — (the encoder report is off, or none came yet)"
    else:
        pairs = zip(report.targets, report.actuals, strict=True)
        letters = settings.WHEELS[: len(report.targets)]
        wheels = "  ".join(f"{w.upper()} {t}/{a}" for w, (t, a) in zip(letters, pairs, strict=True))
        wheels += "  target/actual"
    rows.append(
        reading("wheels", wheels, None if state.report_at is None else now - state.report_at)
    )

    if not any(s.name in state.values for s in settings.SETTINGS):
        rows.append(Row("settings", (("", " not read yet (p reads them)"),)))
    else:
        values = tuple(f"{s.name} {state.values.get(s.name, '?')}" for s in settings.SETTINGS)
        rows.append(Row("settings", pairs=values))

    if session.app is not None:
        app = session.app
        rows += link_rows(app.connected, app.state.stats, app.now(), label="APP port", brief=True)
        rows += telemetry(app.state, app.now())
    return rows


def in_force_text(session: ControlSession) -> str:
    """What drives the car, in words: a turn, a key's motion, a frame sent, or "stopped"."""
    state = session.host.state
    if session.rotation is not None:
        left = state.values.get("pending_angle")
        to_go = "" if left is None else f", {left / 10:g}° to go"
        return f"turning {session.rotation[1]:g}°{to_go}"
    if session.in_force != STOP:
        return session.in_force
    if state.in_force is not None:
        return describe(state.in_force)
    if state.letter is not None:
        page = PAGE_LETTERS[state.app_end.page_letter]
        return f"{state.letter} {letter_name(page, state.letter)} (APP letter)"
    return "stopped"


def _in_force(session: ControlSession) -> list[Row]:
    """What drives the car, then the keys' settings (on a row of their own if they do
    not fit)."""
    text = in_force_text(session)
    what: Span = ("", " stopped") if text == "stopped" else ("on", f" {text} ")
    if session.moving and not session.host.connected:
        return [Row("in force", (("alert", f" {text} "),)), unsent_row()]
    keys = f"speed {session.speed} · r/R {session.angle:g}° · {hold_mode(session.driving)}"
    room = WIDTH - len(" in force ") - len(what[1]) - 3
    if len(keys) <= room:
        return [Row("in force", (what, ("", f"   {keys}")))]
    return [Row("in force", (what,)), Row("", (("", f"{' ' * 10}{keys}"),))]


def control_instruments(session: ControlSession) -> Instruments:
    """What the page's instruments show over the control port."""
    host, state = session.host, session.host.state
    now = host.now()
    table = [(s.name, 0, s.maximum) for s in settings.SETTINGS]
    values = instruments.values(table, state.values, session.unsaved())
    report = state.report
    wheels = None
    if report is not None:
        pairs = zip(settings.WHEELS, report.targets, report.actuals, strict=False)
        wheels = tuple(Wheel(name, target, actual) for name, target, actual in pairs)
    app = session.app
    return Instruments(
        link=instruments.link(host.connected, state.stats, now),
        telemetry=None if app is None else instruments.telemetry(app.state, app.now()),
        in_force=in_force_text(session),
        moving=session.moving,
        stop_unsent=session.moving and not host.connected,
        page=None,
        speed=Value("speed", session.speed, 0, session.top_speed()),
        values=values,
        values_read=any(value.value is not None for value in values),
        wheels=wheels,
        wheels_age=None if state.report_at is None else now - state.report_at,
        driver="UART2" if state.took_over_at is not None else "APP port",
    )


def control_grid(session: ControlSession) -> list[list[str]]:
    names = session.cell_names()
    return [[f"{GLYPHS[r][c]} {names[r][c]}" for c in range(3)] for r in range(3)]


def control_lit(session: ControlSession) -> tuple[int, int] | None:
    if session.in_force == STOP or session.rotation is not None:
        return None
    cells = [(r, c) for r in range(3) for c in range(3)]
    return next(((r, c) for r, c in cells if session.grid_key(r, c) == session.in_force), None)
