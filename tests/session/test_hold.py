"""Hold-to-drive release emulation (docs/design.md, the session layer)."""

from __future__ import annotations

from appmode.session.hold import HoldToDrive


def test_first_press_sends_and_times_out_after_the_first_timeout() -> None:
    hold = HoldToDrive(first_timeout=0.6, repeat_timeout=0.15)
    assert hold.press("A", 0.0) == "A"
    assert not hold.release_due(0.59)
    assert hold.release_due(0.6)
    assert not hold.release_due(0.7), "release is reported once"


def test_repeats_keep_it_alive_and_the_short_timeout_ends_it() -> None:
    hold = HoldToDrive(first_timeout=0.6, repeat_timeout=0.15)
    hold.press("A", 0.0)
    for k in range(1, 30):  # OS auto-repeat every 33 ms, from 0.5 s on
        assert hold.press("A", 0.5 + k * 0.033) is None
    last = 0.5 + 29 * 0.033
    assert not hold.release_due(last + 0.14)
    assert hold.release_due(last + 0.15)


def test_a_new_direction_is_sent_at_once() -> None:
    hold = HoldToDrive()
    assert hold.press("A", 0.0) == "A"
    assert hold.press("C", 0.1) == "C"
    assert hold.current == "C"


def test_stop_key_sends_z_and_forgets_the_direction() -> None:
    hold = HoldToDrive()
    hold.press("A", 0.0)
    assert hold.press("Z", 0.1) == "Z"
    assert not hold.release_due(10.0)


def test_latched_mode_never_times_out() -> None:
    hold = HoldToDrive(latched=True)
    hold.press("E", 0.0)
    assert not hold.release_due(100.0)
    assert hold.press("E", 1.0) is None
