"""A `>` line that a loaded machine sends late shifts the expectations after it by as
much: the board is judged on when it got each command (the real-time suite beside a
second test run sent some lines 0.3 s late and blamed the board)."""

from __future__ import annotations

from appmode.protocol.app import Velocity
from appmode.protocol.transcript import parse_transcript
from appmode.transcript.matcher import Check

TEXT = """# appmode transcript v1
@tolerance 0.1
0.0000 > J
1.0000 > A
1.5000 < {A0:500:0:0}$
2.0000 > Z
2.5000 < {A0:0:0:0}$
"""


def check_sent_late(by: float) -> Check:
    check = Check(parse_transcript(TEXT, "t.transcript"))
    assert [data for _, data in check.due(0.0)] == [b"J"]
    assert [data for _, data in check.due(1.0 + by)] == [b"A"]
    return check


def test_an_answer_to_a_late_line_is_on_time() -> None:
    check = check_sent_late(0.4)
    check.on_record(Velocity(0, 500, 0), 1.55)  # when A was due: too early for it now
    check.on_time(1.85)
    assert check.failure is None and check.matched == 0
    check.on_record(Velocity(0, 500, 0), 1.88)
    assert check.matched == 1
    assert [data for _, data in check.due(2.0)] == [b"Z"]  # on time: no shift
    check.on_time(2.61)
    assert check.failure is not None and "expected {A0:0:0:0}$ at 2.500 s" in check.failure


def test_a_board_that_answers_late_still_fails() -> None:
    check = check_sent_late(0.4)
    check.on_time(2.01)  # 1.5 + 0.4 late + 0.1 tolerance
    assert check.failure is not None
    assert "expected {A0:500:0:0}$ at 1.900 s (±0.1 s); nothing matched by 2.000 s" in (
        check.failure
    )
