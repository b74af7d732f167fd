"""A stop judged on the board's A records (host/stop_check.py), with no I/O."""

from __future__ import annotations

from appmode.host.app.stop_check import SETTLE, TRIES, StopCheck
from appmode.protocol import app, session_end
from appmode.protocol.layouts import SCALED, VELOCITY


def test_a_record_at_rest_confirms_the_stop() -> None:
    check = StopCheck(VELOCITY, b"{}KJZ", since=10.0)
    assert not check.at_rest(app.Velocity(0, 300, 0, 0))
    assert check.on_time(10.5) == b""  # still within SETTLE: wait
    assert check.at_rest(app.Velocity(0, 12, 0, 0))


def test_a_car_that_does_not_stop_gets_a_bounded_number_of_tries() -> None:
    check = StopCheck(VELOCITY, b"{}KJZ", since=0.0)
    now, sent = 0.0, []
    while (again := check.on_time(now)) is not None:
        if again:
            sent.append(again)
        check.at_rest(app.Velocity(0, 500, 0, 0))
        now += 0.05
    assert sent == [b"{}KJZ"] * (TRIES - 1)
    assert now >= TRIES * SETTLE
    assert check.moving == app.Velocity(0, 500, 0, 0)


def test_the_minibalance_layout_reads_its_scaled_fields() -> None:
    check = StopCheck(SCALED, b"KJZ", since=0.0)
    assert not check.at_rest(app.Velocity(0, 210, 100, 0))  # |0.7y| = 210: y = 300
    assert check.at_rest(app.Velocity(0, 0, 100, 0))  # the battery field is no motion


def test_what_is_sent_again_never_closes_a_frame_where_that_applies_it() -> None:
    assert session_end.stop_again(frames_take_letters=True) == b"{}KJZ"
    assert session_end.stop_again(frames_take_letters=False) == b"KJZ"  # minibalance: } applies
