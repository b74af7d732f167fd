"""The status panel shows odd readings without breaking its layout."""

from __future__ import annotations

from appmode.console.panel import BAR, status_fragments
from appmode.console.session import Session


def test_a_battery_out_of_range_fills_the_gauge_and_no_more() -> None:
    session = Session("sim://")
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
