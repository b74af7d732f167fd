"""Reads and verified sets on the control port, as a state machine (no I/O)."""

from __future__ import annotations

import random

import pytest

from appmode.errors import AppmodeError
from appmode.host.control.query import ReadDone, ReadQuery, rotation_done
from appmode.host.control.state import OWED_FOR, ControlState
from appmode.host.outcomes import AGREE, QueryFailed
from appmode.protocol import control, control_decoders, settings


def reply(name: str, value: int) -> control.Reply:
    return control.Reply(settings.read_named(name).reply_id, value)


def frames(data: bytes) -> list[object]:
    return control_decoders.FrameDecoder(control.DriveType.MECANUM).feed(data)


def test_a_read_is_sent_twice_at_once_and_reported_when_the_replies_agree() -> None:
    query = ReadQuery(["max_speed", "pending_angle"], timeout=0.1)
    sent = frames(query.start(0.0))
    assert [type(f).__name__ for f in sent] == ["ReadFrame"] * 4
    assert query.on_reply(reply("max_speed", 500), 0.01) == (b"", None)
    assert query.on_reply(reply("max_speed", 500), 0.01) == (b"", None)
    assert query.on_reply(reply("pending_angle", 7), 0.01) == (b"", None)
    data, outcome = query.on_reply(reply("pending_angle", 7), 0.01)
    assert data == b""
    assert outcome == ReadDone(
        {"max_speed": 500, "pending_angle": 7}, "max_speed = 500, pending_angle = 7"
    )


def test_replies_that_disagree_are_asked_again_and_only_what_is_missing() -> None:
    query = ReadQuery(["max_speed", "max_position"], timeout=0.1)
    query.start(0.0)
    for event in (reply("max_speed", 500), reply("max_speed", 500)):
        query.on_reply(event, 0.01)
    query.on_reply(reply("max_position", 10000), 0.01)
    data, outcome = query.on_reply(reply("max_position", 10001), 0.01)  # a bit flipped
    assert outcome is None
    again = frames(data)
    assert again == [control.ReadFrame(settings.read_named("max_position"))] * 2
    query.on_reply(reply("max_position", 10000), 0.02)
    _, outcome = query.on_reply(reply("max_position", 10000), 0.02)
    assert outcome == ReadDone(
        {"max_speed": 500, "max_position": 10000}, "max_speed = 500, max_position = 10000"
    )


def test_no_reply_resends_each_timeout_then_fails_naming_what_to_check() -> None:
    query = ReadQuery(["max_speed"], timeout=0.1, tries=3, where="/dev/pts/9")
    query.start(0.0)
    assert query.on_time(0.05) == (b"", None)
    assert frames(query.on_time(0.1)[0]) and frames(query.on_time(0.2)[0])
    data, outcome = query.on_time(0.35)
    assert data == b""
    assert isinstance(outcome, QueryFailed)
    assert outcome.text.startswith("no reply reading max_speed on /dev/pts/9 after 3 tries")
    assert "(see appmode protocol 13)" in outcome.text


def test_a_set_is_sent_each_round_until_the_value_reads_back() -> None:
    query = ReadQuery(change=("max_speed", 800), timeout=0.1)
    first = frames(query.start(0.0))
    assert isinstance(first[0], control.SetSetting) and first[0].value == 800
    query.on_reply(reply("max_speed", 500), 0.01)
    data, outcome = query.on_reply(reply("max_speed", 500), 0.01)  # not taken yet
    assert outcome is None and isinstance(frames(data)[0], control.SetSetting)
    query.on_reply(reply("max_speed", 800), 0.02)
    _, outcome = query.on_reply(reply("max_speed", 800), 0.02)
    assert outcome == ReadDone({"max_speed": 800}, "set max_speed = 800 (verified)")


def test_a_set_the_board_refuses_fails_naming_the_value_it_holds() -> None:
    query = ReadQuery(change=("max_speed", 800), timeout=0.1, tries=2)
    query.start(0.0)
    outcome = None
    for t in (0.01, 0.02):
        query.on_reply(reply("max_speed", 500), t)
        _, outcome = query.on_reply(reply("max_speed", 500), t)
    assert isinstance(outcome, QueryFailed)
    assert "max_speed still reads 500" in outcome.text and "after 2 sets of 800" in outcome.text


def test_out_of_range_and_unknown_names_are_refused_before_anything_is_sent() -> None:
    with pytest.raises(ValueError, match="max_speed"):
        ReadQuery(change=("max_speed", 70000))
    with pytest.raises(ValueError, match="unknown read 'top_speed'"):
        ReadQuery(["top_speed"])


def test_the_state_follows_replies_reports_and_the_take_over() -> None:
    state = ControlState()
    state.start_query(ReadQuery(["system_mode"]), 0.0)
    sent = state.take_outbox()
    state.sent(sent[:9], 0.0)
    assert state.took_over_at is None
    state.sent(sent[9:], 0.001)
    assert state.took_over_at == 0.001
    answer = control.encode(control.Reply(9, 0x41)) * 2
    report = control.encode(control.EncoderReport((300,) * 4, (290,) * 4))
    events = state.feed(b"\x00" + answer + report, 0.01)
    assert ReadDone({"system_mode": 0x41}, "system_mode = 65") in events
    assert state.values == {"system_mode": 0x41}
    assert state.drive is control.DriveType.MECANUM  # learnt from the mode read
    assert state.report is not None and state.report.actuals == (290,) * 4
    assert state.stats.errors == 1
    state.sent(control.encode(control.VelocityFrame(0, 300, 0)), 0.02)
    assert isinstance(state.in_force, control.VelocityFrame)
    state.sent(control.STOP, 0.03)
    assert state.in_force is None


def test_a_late_reply_to_an_earlier_query_does_not_answer_the_next() -> None:
    """A read's first round timed out on a loaded host and was sent again; the first
    round's replies ended it, the second's came after: they are not the next read's
    (which took them, and said 800 after `defaults` had made it 500). A reply lost to
    noise costs the next read at most that reply."""
    state = ControlState()
    max_speed = settings.read_named("max_speed").reply_id

    def replies(value: int) -> bytes:
        return control.encode(control.Reply(max_speed, value)) * AGREE

    state.start_query(ReadQuery(["max_speed"]), 0.0)
    state.sent(state.take_outbox(), 0.0)
    assert state.tick(0.15) is None  # no reply in time: the round again
    state.sent(state.take_outbox(), 0.15)
    assert ReadDone({"max_speed": 800}, "max_speed = 800") in state.feed(replies(800), 0.16)
    state.start_query(ReadQuery(["max_speed"]), 0.2)  # the board was set to 500 meanwhile
    state.sent(state.take_outbox(), 0.2)
    assert not [e for e in state.feed(replies(800), 0.21) if isinstance(e, ReadDone)]
    assert ReadDone({"max_speed": 500}, "max_speed = 500") in state.feed(replies(500), 0.22)
    one = control.encode(control.Reply(max_speed, 500))
    state.start_query(ReadQuery(["max_speed"]), 0.3)  # one of its replies is lost
    state.sent(state.take_outbox(), 0.3)
    assert not [e for e in state.feed(one, 0.31) if isinstance(e, ReadDone)]
    assert state.tick(0.45) is None
    state.sent(state.take_outbox(), 0.45)
    assert ReadDone({"max_speed": 500}, "max_speed = 500") in state.feed(replies(500), 0.46)
    state.start_query(ReadQuery(["max_speed"]), 0.5)  # the lost one costs it one reply
    state.sent(state.take_outbox(), 0.5)
    assert not [e for e in state.feed(replies(500), 0.51) if isinstance(e, ReadDone)]
    assert ReadDone({"max_speed": 500}, "max_speed = 500") in state.feed(one, 0.52)


def test_reads_a_board_never_answers_are_not_kept_for_ever() -> None:
    """The reference firmware answers no read (§13): what a host sent it over 2 s
    (OWED_FOR) ago is forgotten, not kept for a whole session."""
    state = ControlState()
    read = control.encode(control.read("max_speed"))
    for tick in range(1000):  # ten reads a second for 100 s, no reply
        state.sent(read, tick / 10)
    assert len(state._owed) <= OWED_FOR * 10 + 1, len(state._owed)


def test_reads_lost_to_noise_do_not_starve_the_queries_after() -> None:
    """One read in five, or its reply, lost: every query of the ten settings still ends
    in a few rounds. The board answers reads in the order sent, so the reads before the
    one a reply answers were lost; before, they were taken as owed for 2 s, the replies
    after them given to earlier queries, and from the seventh query on each took 19 or
    20 of its 20 tries."""
    lost = random.Random(4)
    state = ControlState()
    now, rounds = 0.0, []
    for _ in range(30):
        query = ReadQuery([s.name for s in settings.SETTINGS], tries=20)
        state.start_query(query, now)
        outcome: object = None
        while outcome is None:
            sent = state.take_outbox()
            state.sent(sent, now)
            answered = [f for f in frames(sent) if lost.random() >= 0.2]
            now += 0.01
            data = b"".join(
                control.encode(control.Reply(f.read.reply_id, 7))  # type: ignore[attr-defined]
                for f in answered
            )
            done = [e for e in state.feed(data, now) if isinstance(e, (ReadDone, QueryFailed))]
            now += 0.1
            outcome = done[0] if done else state.tick(now)
        assert isinstance(outcome, ReadDone), outcome
        rounds.append(query.rounds)
    assert max(rounds) <= 6, rounds  # 2–5


def test_a_rotation_ends_at_zero_and_fails_past_its_timeout() -> None:
    assert rotation_done(0, 30.0, 20.0)
    assert not rotation_done(450, 1.0, 20.0)
    with pytest.raises(AppmodeError, match="45° still to turn after 20 s"):
        rotation_done(450, 20.5, 20.0)
