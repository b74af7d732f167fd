"""What the control port's session shows: who drives, the frame in force, the encoder
report (target and actual per wheel), the ten settings, and the APP port's records when
the session holds both ports."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from appmode.protocol import settings
from appmode.protocol.control_view import describe
from appmode.protocol.directions import PAGE_LETTERS, letter_name
from appmode.session import instruments
from appmode.session.instruments import Instruments, Value, Wheel
from appmode.session.rows import (
    WIDTH,
    Row,
    Span,
    link_rows,
    reading,
    telemetry,
    unsent_row,
)

if TYPE_CHECKING:
    from appmode.host.app.client import Host
    from appmode.host.control.client import ControlHost
    from appmode.protocol.params import DriveType

SILENT_HINT = "check the wiring and that the car is on; appmode doctor finds its port"
STOP = "stop"
"""What is in force when no motion is."""


@dataclass(frozen=True, slots=True)
class Keys:
    """What the session holds that its status shows, beside its hosts: the motion its
    keys drive (or `stop`), a turn under way (when, degrees), the keys' speed and angle,
    how keys hold, whether anything is in force, what was set and not saved."""

    in_force: str
    rotation: tuple[float, float] | None
    speed: int
    top_speed: int
    angle: float
    hold: str
    moving: bool
    unsaved: tuple[str, ...]
    drive: DriveType | None


def control_rows(host: ControlHost, app: Host | None, keys: Keys) -> list[Row]:
    state = host.state
    now = host.now()
    rows = link_rows(
        host.connected, state.stats, now, "messages", SILENT_HINT, latency=host.latency
    )

    drive = keys.drive
    by_drive: Span = ("", f" · drive {'? (reading)' if drive is None else drive.cli_name}")
    if state.took_over_at is not None:
        since = f" drives: this session's frames since {state.took_over_at:.2f} s"
        rows.append(Row("control", (("on", " UART2 "), ("", since), by_drive)))
    else:
        until = f" APP port, until UART2 receives {state.takeover_byte} bytes"
        rows.append(Row("control", (("", until), by_drive)))

    rows += _in_force(host, keys)

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

    if app is not None:
        rows += link_rows(app.connected, app.state.stats, app.now(), label="APP port", brief=True)
        rows += telemetry(app.state, app.now())
    return rows


def in_force_text(host: ControlHost, keys: Keys) -> str:
    """What drives the car, in words: a turn, a key's motion, a frame sent, an APP
    letter, or "stopped"."""
    state = host.state
    if keys.rotation is not None:
        left = state.values.get("pending_angle")
        to_go = "" if left is None else f", {left / 10:g}° to go"
        return f"turning {keys.rotation[1]:g}°{to_go}"
    if keys.in_force != STOP:
        return keys.in_force
    if state.in_force is not None:
        return describe(state.in_force)
    if state.letter is not None:
        page = PAGE_LETTERS[state.app_end.page_letter]
        return f"{state.letter} {letter_name(page, state.letter)} (APP letter)"
    return "stopped"


def _in_force(host: ControlHost, keys: Keys) -> list[Row]:
    """What drives the car, then the keys' settings (on a row of their own if they do
    not fit)."""
    text = in_force_text(host, keys)
    what: Span = ("", " stopped") if text == "stopped" else ("on", f" {text} ")
    if keys.moving and not host.connected:
        return [Row("in force", (("alert", f" {text} "),)), unsent_row()]
    shown = f"speed {keys.speed} · r/R {keys.angle:g}° · {keys.hold}"
    room = WIDTH - len(" in force ") - len(what[1]) - 3
    if len(shown) <= room:
        return [Row("in force", (what, ("", f"   {shown}")))]
    return [Row("in force", (what,)), Row("", (("", f"{' ' * 10}{shown}"),))]


def control_instruments(host: ControlHost, app: Host | None, keys: Keys) -> Instruments:
    """What the page's instruments show over the control port."""
    state = host.state
    now = host.now()
    table = [(s.name, 0, s.maximum) for s in settings.SETTINGS]
    values = instruments.values(table, state.values, keys.unsaved)
    report = state.report
    wheels = None
    if report is not None:
        pairs = zip(settings.WHEELS, report.targets, report.actuals, strict=False)
        wheels = tuple(Wheel(name, target, actual) for name, target, actual in pairs)
    return Instruments(
        link=instruments.link(host.connected, state.stats, now, host.latency),
        telemetry=None if app is None else instruments.telemetry(app.state, app.now()),
        in_force=in_force_text(host, keys),
        moving=keys.moving,
        stop_unsent=keys.moving and not host.connected,
        page=None,
        speed=Value("speed", keys.speed, 0, keys.top_speed),
        values=values,
        values_read=any(value.value is not None for value in values),
        wheels=wheels,
        wheels_age=None if state.report_at is None else now - state.report_at,
        driver="UART2" if state.took_over_at is not None else "APP port",
    )


def control_lit(names: list[list[str]], keys: Keys) -> tuple[int, int] | None:
    """The cell of the motion the keys drive (none while turning or stopped)."""
    if keys.in_force == STOP or keys.rotation is not None:
        return None
    cells = [(r, c) for r in range(3) for c in range(3)]
    return next(((r, c) for r, c in cells if names[r][c] == keys.in_force), None)
