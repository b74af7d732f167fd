"""The status panel shows odd readings without breaking its layout."""

from __future__ import annotations

import os
import pty
import time
import tty

from prompt_toolkit.formatted_text import StyleAndTextTuples
from prompt_toolkit.utils import get_cwidth

from appmode.console.panel import status_fragments
from appmode.console.waves import LEVELS
from appmode.session.base import BaseSession
from appmode.session.hold import HoldToDrive
from appmode.session.rows import BAR, WIDTH
from tests.support.sessions import session as open_board


def test_a_battery_out_of_range_fills_the_gauge_and_no_more() -> None:
    session = open_board("sim://")
    try:
        for reading, filled in ((-740, 0), (250, BAR)):
            session.host.state.feed(b"{B0:0:0:%d}$" % reading, session.host.now())
            text = "".join(part[1] for part in status_fragments(session))
            line = next(row for row in text.splitlines() if "battery" in row)
            assert f"{reading} %" in line and len(line) < 60, line
            gauge = line[line.index("[") + 1 : line.index("]")]
            assert gauge == "#" * filled + "." * (BAR - filled)
    finally:
        session.close()


def _settled(url: str = "sim://", seconds: float = 1.2, letter: str | None = None) -> BaseSession:
    session = open_board(url, HoldToDrive(latched=True))
    session.start()
    if letter:
        session.press(letter)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        session.tick()
        time.sleep(0.02)
    return session


def _lines(fragments: StyleAndTextTuples) -> list[str]:
    return "".join(part[1] for part in fragments).splitlines()


def test_every_line_fits_80_columns_with_the_grid_the_waveforms_and_the_help() -> None:
    session = _settled(letter="A")
    try:
        session.switch_page("K")
        session.driving.latched = False
        session.press("H")  # the longest direction name, in hold mode
        views = {
            "grid": _lines(status_fragments(session)),
            "waves": _lines(status_fragments(session, waveforms=True)),
            "help": session.help_lines,
        }
    finally:
        session.close()
    for name, lines in views.items():
        widths = [sum(get_cwidth(ch) for ch in line) for line in lines]
        assert max(widths) <= WIDTH, (name, lines[widths.index(max(widths))])
    waves = views["waves"]
    vy = next(line for line in waves if line.startswith(" vy"))
    assert any(block in vy for block in LEVELS[4:]), vy  # the car sped up: a rising line
    assert len(views["grid"]) + 1 + 3 <= 24 and len(waves) + 1 + 3 <= 24  # + rule + log


def test_a_silent_port_is_not_called_up() -> None:
    master, slave = pty.openpty()  # nothing will ever answer on it
    tty.setraw(slave)
    try:
        session = _settled(os.ttyname(slave), seconds=2.3)
        try:
            text = "\n".join(_lines(status_fragments(session)))
        finally:
            session.close()
    finally:
        os.close(master)
        os.close(slave)
    assert "port open, nothing received" in text and "appmode doctor" in text
    assert "link up" not in text
    hint = next(line for line in text.splitlines() if "appmode doctor" in line)
    assert hint.strip().endswith("appmode doctor finds its port and baud rate") and len(hint) <= 80


def test_old_readings_are_shown_with_their_age() -> None:
    session = _settled(letter="A")
    try:
        session.host.close()  # the link is lost: no more records
        time.sleep(0.8)
        text = "\n".join(_lines(status_fragments(session)))
    finally:
        session.close()
    assert "LINK LOST" in text
    velocity = next(line for line in text.splitlines() if "velocity" in line)
    assert " s ago)" in velocity, velocity
