"""The host against the minibalance board in-process (sim://?profile=minibalance, paced
in real time): start-up text, B first, 60-90 ms between records and lost reads."""

from __future__ import annotations

import time

from appmode.board.profiles import MINIBALANCE
from appmode.host.client import Host
from appmode.ports.sim import SimSerial

URL = "sim://?profile=minibalance"


def test_s13_a_read_at_power_up_gets_past_the_start_up_text() -> None:
    with Host(URL) as host:
        started = time.monotonic()
        assert host.read_params() == MINIBALANCE.defaults
        took = time.monotonic() - started
        assert host.state.stats.errors >= 1, "the ten text lines decode to nothing"
        assert took < 2.0, f"{took:.2f} s: the first C comes after the text, not a timeout"


def test_s13_a_set_whose_read_is_lost_during_a_c_record_is_still_verified() -> None:
    with Host(URL) as host:
        host.read_params()
        sim = host.link
        assert isinstance(sim, SimSerial) and sim.board is not None
        board = sim.board
        host.send(b"{Q:P}")
        while not board._c_on_wire_until > sim._now():  # wait for the C to start going out
            host.poll(0.0005)
        values = host.set_param(0, 100)  # its {Q:P} arrives while that C is on the wire
        notes = [n.text for n in board.take_notes()]
        assert any(n.startswith("{Q:P}: lost") for n in notes), notes
        assert values[0] == 100
        assert sum("max_speed = 100" in n for n in notes) >= 1
        host.set_param(0, 30)
