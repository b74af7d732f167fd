"""What the APP port's session shows: the link, the telemetry, the page and the letter
in force (what the board was last sent), the parameters; as rows for the terminal and as
values for the page's instruments. It reads the host and what the session says of its
keys and of the parameters it last saved."""

from __future__ import annotations

from typing import TYPE_CHECKING

from appmode.protocol import param_values
from appmode.protocol.directions import PAGE_LETTERS, PAGE_NAMES, STOP_LETTER, grid_for, letter_name
from appmode.session import instruments
from appmode.session.instruments import Instruments, Value
from appmode.session.rows import GLYPHS, Row, Span, link_rows, telemetry, unsent_row

if TYPE_CHECKING:
    from appmode.host.app.client import Host
    from appmode.protocol.directions import Page


def page_of(host: Host) -> Page:
    """The app's page the board was last switched to."""
    return PAGE_LETTERS[host.state.end.page_letter]


def page_name(host: Host) -> str:
    """The app's page the board is on, as its profile names it."""
    letter = host.state.end.page_letter
    return host.state.layout.profile.pages.get(letter, PAGE_NAMES[letter])


def in_force(host: Host) -> str:
    """The drive letter the board was last sent and follows, or `Z`."""
    return host.state.end.letter or STOP_LETTER


def app_rows(host: Host, hold: str) -> list[Row]:
    """The panel's rows; `hold`: how the keys hold (latched, or their time-outs)."""
    state = host.state
    now = host.now()
    letter, page = in_force(host), page_of(host)
    moving = state.end.moving
    rows = link_rows(host.connected, state.stats, now, latency=host.latency)
    rows += telemetry(state, now)
    shown: tuple[Span, ...] = (
        ("", f" {page.value} ({state.end.page_letter} {page_name(host)})   "),
        ("label", "in force "),
        ("on" if moving else "", f" {letter} {letter_name(page, letter)} "),
        ("", f"   {hold}"),
    )
    rows.append(Row("page", shown))
    if moving and not host.connected:
        rows.append(unsent_row())
    if state.letters_ignored:
        ignored: tuple[Span, ...] = (
            ("warn", " the car does not follow the letters "),
            ("", "  UART2 may have taken over (§8.3)"),
        )
        rows.append(Row("control", ignored))
    record = state.params
    if record is None:
        rows.append(Row("params", (("", " not read yet (p reads them)"),)))
    else:
        pairs = zip(state.layout.params, record.values, strict=False)
        values = tuple(f"{p.name} {param_values.to_user(p, v)}" for p, v in pairs)
        rows.append(Row("params", pairs=values))
    return rows


def app_instruments(host: Host, saved: tuple[int, ...] | None) -> Instruments:
    """The page's instruments; `saved`: the parameters as last read or saved."""
    state = host.state
    now = host.now()
    specs = state.layout.params
    table = [(p.name, p.minimum, p.maximum) for p in specs]
    names = [p.name for p in specs]
    now_values = () if state.params is None else state.params.values
    read = dict(zip(names, now_values, strict=False))
    unsaved = [
        name for name, old, new in zip(names, saved or (), now_values, strict=False) if old != new
    ]
    values = instruments.values(table, read, unsaved, [p.scale for p in specs])
    moving = state.end.moving
    return Instruments(
        link=instruments.link(host.connected, state.stats, now, host.latency),
        telemetry=instruments.telemetry(state, now),
        in_force=letter_name(page_of(host), in_force(host)) if moving else "stopped",
        moving=moving,
        stop_unsent=moving and not host.connected,
        page=page_name(host),
        speed=_speed_value(host, values),
        values=values,
        values_read=state.params is not None,
        wheels=None,
        wheels_age=None,
        driver=None,
    )


def _speed_value(host: Host, values: tuple[Value, ...]) -> Value | None:
    """What the speed keys change: the speed parameter, or (a firmware whose letters
    change its speed) those letters, whose speed no record shows; None: nothing."""
    layout = host.state.layout
    if layout.speed_index is not None:
        return values[layout.speed_index]
    keys = layout.profile.speed_keys
    return Value(f"speed ({'/'.join(keys)})", None, 0, 0) if keys else None


def app_grid(host: Host) -> list[list[str]]:
    """The grid's cells as shown: letter, arrow and what it does on the page."""
    page = page_of(host)
    return [
        [f"{letter} {GLYPHS[r][c]} {letter_name(page, letter)}" for c, letter in enumerate(row)]
        for r, row in enumerate(grid_for(page))
    ]


def app_cell_names(host: Host) -> list[list[str]]:
    page = page_of(host)
    return [[letter_name(page, x) for x in row] for row in grid_for(page)]


def app_lit(host: Host) -> tuple[int, int] | None:
    """The cell of the letter in force (none when stopped)."""
    letter = in_force(host)
    if letter == STOP_LETTER:
        return None
    letters = grid_for(page_of(host))
    cells = [(r, c) for r in range(3) for c in range(3)]
    return next(((r, c) for r, c in cells if letters[r][c] == letter), None)
