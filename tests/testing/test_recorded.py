"""A board's recording checked against a transcript's expectations (transcript/recorded.py)."""

from __future__ import annotations

from appmode.protocol.transcript import parse_transcript
from appmode.transcript.recorded import check_recorded

EXPECTED = """\
# appmode transcript v1
0.000 > J
0.000 > A
0.600 < {A0:1..500:0:0}$
1.000 > Z
1.600 < {A0:0:0:0}$
"""


def recording(*lines: str) -> str:
    return "\n".join(["# appmode transcript v1", *lines, ""])


def check(expected: str, recorded: str) -> str | None:
    return check_recorded(
        parse_transcript(expected, "expected.transcript"), parse_transcript(recorded, "rec")
    ).failure


def test_a_recording_that_meets_the_expectations_passes() -> None:
    # the host sent later than the transcript says: times count from its real sends
    assert (
        check(
            EXPECTED,
            recording(
                "2.000 < {A0:0:0:0}$",
                "3.500 > J",
                "3.510 > A",
                "3.550 < {A0:0:0:0}$",
                "4.050 < {A0:480:0:0}$",
                "5.000 > Z",
                "5.500 < {A0:0:0:0}$",
            ),
        )
        is None
    )


def test_other_units_between_the_expected_sends_are_allowed() -> None:
    assert (
        check(
            EXPECTED,
            recording(
                "0.000 > {Q:P}",
                "0.010 > J",
                "0.060 < {C500:10000:20:0:10:10:10:0:0}$",
                "0.100 > A",
                "0.600 < {A0:300:0:0}$",
                "1.000 > Z",
                "1.500 < {A0:0:0:0}$",
            ),
        )
        is None
    )


def test_a_send_the_host_never_made_is_named() -> None:
    failure = check(EXPECTED, recording("0.000 > J", "0.600 < {A0:0:0:0}$"))
    assert failure == (
        "expected.transcript:3: expected the host to send A; the recording (to 0.600 s) "
        "has no such unit after the sends before it"
    )


def test_a_record_that_does_not_match_fails_with_what_came_instead() -> None:
    failure = check(
        EXPECTED,
        recording("0.000 > J", "0.000 > A", "0.600 < {A0:900:0:0}$", "1.200 < {A0:900:0:0}$"),
    )
    assert failure is not None
    assert failure.startswith("expected.transcript:4: expected {A0:1..500:0:0}$ at 0.600 s")
    assert "got {A0:900:0:0}$ at 0.600 s instead" in failure


def test_a_recording_that_ends_too_soon_says_to_wait() -> None:
    failure = check(EXPECTED, recording("0.000 > J", "0.100 > A", "0.300 < {A0:0:0:0}$"))
    assert failure is not None
    assert "expected {A0:1..500:0:0}$ at 0.700 s" in failure
    assert "the recording ends at 0.300 s" in failure


def test_a_record_before_its_send_does_not_count() -> None:
    # {A0:0:0:0}$ is expected after Z: the one before Z was sent is no answer to it
    failure = check(
        EXPECTED,
        recording(
            "0.000 > J",
            "0.000 > A",
            "0.500 < {A0:300:0:0}$",
            "0.900 < {A0:0:0:0}$",
            "1.000 > Z",
            "2.200 < {A0:300:0:0}$",
        ),
    )
    assert failure is not None and "expected.transcript:6: expected {A0:0:0:0}$" in failure


def test_uart2_units_are_matched_by_their_bytes() -> None:
    expected = """\
# appmode transcript v1
0.000 2> FF FE 80 80 11 00 00 00 00 00
0.020 2< 23 01 00 00 01 F4
"""
    good = recording("5.000 2> FF FE 80 80 11 00 00 00 00 00", "5.010 2< 23 01 00 00 01 F4")
    assert check(expected, good) is None
    bad = ["5.000 2> FF FE 80 80 11 00 00 00 00 00", "5.010 2< 23 01 00 00 03 20"]
    failure = check(expected, recording(*bad, "6.000 < {A0:0:0:0}$"))
    assert failure == (
        "expected.transcript:3: expected 23 01 00 00 01 F4 at 5.020 s (±0.5 s); nothing "
        "matched by 5.520 s; got 23 01 00 00 03 20 at 5.010 s instead"
    )
    failure = check(expected, recording(*bad))
    assert failure is not None
    assert "the recording ends at 5.010 s (it got 23 01 00 00 03 20 at 5.010 s)" in failure


def test_one_expected_line_of_several_units_is_matched_unit_by_unit() -> None:
    expected = "# appmode transcript v1\n0.000 > JA\n0.500 < {A0:1..500:0:0}$\n"
    assert check(expected, recording("1.000 > J", "1.001 > A", "1.400 < {A0:20:0:0}$")) is None
    failure = check(expected, recording("1.000 > A", "1.001 > J", "1.400 < {A0:20:0:0}$"))
    assert failure is not None and "expected the host to send JA" in failure


def test_each_expectation_is_timed_from_the_send_above_it() -> None:
    # Z came early (0.05 s, not 1.0): the A record expected 0.6 s after A is still
    # timed from A, not pulled back by Z; the stop's record is timed from Z
    assert (
        check(
            EXPECTED,
            recording(
                "0.000 > J",
                "0.000 > A",
                "0.050 > Z",
                "0.300 < {A0:150:0:0}$",
                "0.700 < {A0:0:0:0}$",
            ),
        )
        is None
    )


def test_a_deadline_still_to_come_is_reported_as_such() -> None:
    verdict = check_recorded(
        parse_transcript(EXPECTED, "expected.transcript"),
        parse_transcript(recording("0.000 > J", "0.000 > A", "0.300 < {A0:0:0:0}$"), "rec"),
        end=0.4,
    )
    assert verdict.wait == 1.1 and verdict.failure is not None
    late = check_recorded(
        parse_transcript(EXPECTED, "expected.transcript"),
        parse_transcript(recording("0.000 > J", "0.000 > A", "0.300 < {A0:0:0:0}$"), "rec"),
        end=1.2,
    )
    assert late.wait is None
    assert late.failure is not None and "nothing matched by 1.100 s" in late.failure
