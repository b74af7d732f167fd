"""The host against the minibalance board in-process (sim://?profile=minibalance, paced
in real time): start-up text, B first, 60-90 ms between records and lost reads."""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

from appmode.board.profiles import MINIBALANCE
from appmode.host.app.client import Host
from appmode.host.events import BoardWarning
from appmode.ports.sim import SimSerial

URL = "sim://?profile=minibalance"


def test_s13_a_read_at_power_up_gets_past_the_start_up_text() -> None:
    with Host(URL) as host:
        started = time.monotonic()
        assert host.read_params() == MINIBALANCE.defaults
        took = time.monotonic() - started
        stats = host.state.stats
        assert stats.errors == 0 and stats.skipped > 300, "the start-up text is no error"
        assert took < 2.0, f"{took:.2f} s: the first C comes after the text, not a timeout"


def test_s13_a_set_whose_read_is_lost_during_a_c_record_is_still_verified() -> None:
    with Host(URL) as host:
        host.read_params()
        sim = host.link
        assert isinstance(sim, SimSerial) and sim.board is not None
        board = sim.board
        deadline = time.monotonic() + 10
        before = board._c_on_wire_until
        host.send(b"{Q:P}")
        while not board._c_on_wire_until > sim._now():  # wait for the C to start going out
            assert time.monotonic() < deadline, "no C record went out"
            if board._c_on_wire_until != before:  # it went out between two looks (a host
                before = board._c_on_wire_until  # not scheduled meanwhile): ask again
                host.send(b"{Q:P}")
            host.poll(0.0005)
        values = host.set_param(0, 100)  # its {Q:P} arrives while that C is on the wire
        notes = [n.text for n in board.take_notes()]
        assert any(n.startswith("{Q:P}: lost") for n in notes), notes
        assert values[0] == 100
        assert sum("max_speed = 100" in n for n in notes) >= 1
        host.set_param(0, 30)


def _warnings_after_a_read_while_driving(frames_stop: bool) -> list[str]:
    """J A until the car moves, then {Q:P}: on the reference firmware the frame's `{`
    stops the car (§13), and it coasts to a stand."""
    profile = MINIBALANCE if frames_stop else replace(MINIBALANCE, steer_in_frames=False)
    with Host(URL, profile=profile) as host:
        list(host.events(2.0))  # the board boots: motors from 1.9 s (§13.1)
        host.send(b"JA")
        list(host.events(0.7))
        host.send(b"{Q:P}")
        events = list(host.events(2.0))
    return [event.text for event in events if isinstance(event, BoardWarning)]


def test_a_frame_that_stops_a_minibalance_car_is_no_take_over() -> None:
    """A host that knows the frame stops the car, and one that does not, side by side
    (each on a board of its own: they mostly wait)."""
    with ThreadPoolExecutor(2) as pool:
        knows, blind = pool.map(_warnings_after_a_read_while_driving, (True, False))
    assert knows == []
    assert any("may have taken over" in text for text in blind), "what it said before"
