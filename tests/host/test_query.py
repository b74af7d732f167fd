"""Parameter reads and verified sets as a state machine (client.HostState + query)."""

from __future__ import annotations

import pytest

from appmode.host.app.query import NOISY_LEAD, ParamQuery, QueryDone
from appmode.host.app.state import HostState
from appmode.host.outcomes import QueryFailed
from appmode.protocol import params
from appmode.protocol.app import ParamsRecord, encode


def c_record(**changes: int) -> bytes:
    values = list(params.DEFAULTS)
    for name, value in changes.items():
        values[params.BY_NAME[name].index] = value
    return encode(ParamsRecord(tuple(values)))


GARBLED_C = b"{C500:10000:20:0:1\x000:10:10:0:0}$"
"""A C record whose NUL in a value the decoder rejects."""


def outcomes(events: list[object]) -> list[object]:
    return [e for e in events if isinstance(e, (QueryDone, QueryFailed))]


def test_read_ends_when_two_c_records_asked_for_separately_agree() -> None:
    state = HostState()
    state.start_query(ParamQuery(), 0.0)
    assert state.take_outbox() == b"{Q:P}"
    assert outcomes(state.feed(c_record(), 0.1)) == []
    assert state.take_outbox() == b"{Q:P}", "asks again to confirm"
    [done] = outcomes(state.feed(c_record(), 0.2))
    assert isinstance(done, QueryDone) and done.values == params.DEFAULTS
    assert state.query is None


def test_a_corrupted_digit_is_not_reported() -> None:
    """Issue 22.6: once the link shows noise, a value must lead every other by
    NOISY_LEAD votes (a digit lost the same way twice must not win)."""
    state = HostState()
    state.start_query(ParamQuery(), 0.0)
    state.feed(c_record(max_speed=900), 0.1)  # a digit hit by noise: well-formed, wrong
    for i in range(NOISY_LEAD):
        assert outcomes(state.feed(c_record(), 0.2 + 0.1 * i)) == []
    [done] = outcomes(state.feed(c_record(), 0.7))
    assert isinstance(done, QueryDone) and done.values[0] == 500


def test_a_wrong_value_seen_twice_does_not_win_against_the_true_one() -> None:
    state = HostState()
    state.start_query(ParamQuery(), 0.0)
    wrong = c_record(max_speed=50)  # 500 with a zero lost, as it often is
    for record in (c_record(), wrong, wrong, c_record(), wrong):
        assert outcomes(state.feed(record, 0.1)) == []
    for _ in range(4):  # 500 leads by 1, 2, 3 votes: not yet
        assert outcomes(state.feed(c_record(), 0.2)) == []
    [done] = outcomes(state.feed(c_record(), 0.3))  # by NOISY_LEAD: reported
    assert isinstance(done, QueryDone) and done.values[0] == 500


def test_a_garbled_c_record_is_asked_for_again_at_once() -> None:
    state = HostState()
    state.start_query(ParamQuery(), 0.0)
    state.take_outbox()
    state.feed(GARBLED_C, 0.1)
    assert state.take_outbox() == b"{Q:P}"
    assert state.stats.errors == 1 and state.params is None


def test_garbled_answers_give_their_requests_back_up_to_as_many_again() -> None:
    """A garbled answer is no silence: with tries=2 a noisy read has 8 requests, and 6
    garbled answers before 4 agreeing ones would have spent them (one set in about 400
    under the suite's moderate faults did)."""
    state = HostState()
    state.start_query(ParamQuery(tries=2), 0.0)
    for i in range(6):
        assert outcomes(state.feed(GARBLED_C, 0.1 * i)) == []
    for i in range(3):
        assert outcomes(state.feed(c_record(), 1.0 + 0.1 * i)) == []
    [done] = outcomes(state.feed(c_record(), 1.5))
    assert isinstance(done, QueryDone) and done.values == params.DEFAULTS


def test_a_link_that_only_garbles_still_ends_the_query() -> None:
    state = HostState()
    state.feed(c_record(), 0.0)  # a board, then a link that garbles all it carries
    state.start_query(ParamQuery(tries=2), 0.0)
    sent = state.take_outbox().count(b"{Q:P}")
    failed: list[object] = []
    while not failed:
        failed = outcomes(state.feed(GARBLED_C, 0.1 * sent))
        sent += state.take_outbox().count(b"{Q:P}")
    assert sent == 16, "8 requests, and 8 given back by garbled answers"
    assert isinstance(failed[0], QueryFailed) and "the link is noisy" in failed[0].text


def test_read_resends_on_timeout_then_fails_with_a_clear_error() -> None:
    state = HostState()
    state.start_query(ParamQuery(timeout=0.5, tries=2, where="/dev/ttyUSB0"), 0.0)
    state.take_outbox()
    assert state.tick(0.4) is None and state.take_outbox() == b""
    for k in range(1, 4):
        assert state.tick(0.5 * k) is None and state.take_outbox() == b"{Q:P}"
    outcome = state.tick(2.0)
    assert isinstance(outcome, QueryFailed)
    assert "nothing came from /dev/ttyUSB0: sent {Q:P} 4 times and no 2 C records" in (outcome.text)


def test_set_is_verified_by_agreeing_c_records_read_after_it() -> None:
    state = HostState()
    state.feed(c_record(), 0.0)  # what the host read before the set
    state.start_query(ParamQuery((0, 800)), 0.0)
    assert state.take_outbox() == b"{0:800}{Q:P}"
    assert outcomes(state.feed(c_record(), 0.02)) == []  # already on its way: old value
    assert outcomes(state.feed(c_record(max_speed=800), 0.1)) == []
    [done] = outcomes(state.feed(c_record(max_speed=800), 0.2))
    assert isinstance(done, QueryDone) and done.text == "max_speed = 800 (verified)"


def test_set_that_never_takes_is_retried_then_fails_naming_the_value_read() -> None:
    state = HostState()
    state.start_query(ParamQuery((5, 42), timeout=0.5, tries=2), 0.0)
    assert state.take_outbox() == b"{5:42}{Q:P}"
    state.feed(c_record(), 0.1)
    state.feed(c_record(), 0.2)  # agreed: the set did not take
    assert state.take_outbox() == b"{Q:P}{5:42}{Q:P}", "confirm, then set again"
    state.feed(c_record(), 0.3)
    [failed] = outcomes(state.feed(c_record(), 0.4))
    assert isinstance(failed, QueryFailed)
    assert failed.text == "set velocity_kp = 42 was not taken: velocity_kp reads 10"


def test_query_rejects_out_of_range_before_sending() -> None:
    with pytest.raises(ValueError, match="max_speed"):
        ParamQuery((0, 70000))


def test_the_records_of_a_noisy_session_do_not_make_a_lost_zero_the_answer() -> None:
    """Issue 22.6, as seeded session 32 under heavy faults saw it: a zero lost from
    max_position 10000 twice in a row (any of its four zeros gives 1000) was reported."""
    state = HostState()
    state.start_query(ParamQuery(tries=10), 0.0)
    seen = [100000, None, 1000, 10000, None, 1000, 1000]  # None: a garbled C record
    for i, max_position in enumerate(seen):
        if max_position is None:
            state.feed(b"{C500:1OK\r\n0000:20:0:10:10:10:0:0}$", 0.1 * i)
        else:
            assert outcomes(state.feed(c_record(max_position=max_position), 0.1 * i)) == []
    done: list[object] = []
    t = 1.0
    while not done:
        done = outcomes(state.feed(c_record(), t))
        t += 0.1
    assert isinstance(done[0], QueryDone) and done[0].values[1] == 10000


def test_a_set_garbled_on_its_way_is_not_reported_as_taken() -> None:
    """Issue 22.6, as seeded session 862 saw it: `{5:4242}` reached the board as
    42422; its C records, with a 2 lost, read 4242 too. Records of a value other than
    the one read before the set are votes against, not history."""
    state = HostState()
    state.feed(c_record(), 0.0)
    state.start_query(ParamQuery((5, 4242), tries=10), 0.0)
    for i, kp in enumerate([42422, 4242, 42422, 4242, 42422, 42422, 42422]):
        events = outcomes(state.feed(c_record(velocity_kp=kp), 0.1 * (i + 1)))
        assert not any(isinstance(e, QueryDone) for e in events), f"record {i}"


def test_a_set_damaged_then_lost_once_is_sent_again_not_called_refused() -> None:
    """CI, tests/line/test_faults.py under moderate faults: `{7:123456}` reached the board
    as 12456, and the frame sent again was lost, so two rounds read 12456 and the set was
    called refused. A third frame is sent; it takes."""
    state = HostState()
    state.feed(c_record(), 0.0)
    state.start_query(ParamQuery((5, 4242), tries=10), 0.0)
    assert state.take_outbox() == b"{5:4242}{Q:P}"
    t = 0.0
    for _ in range(2):  # the damaged value; then the frame sent again is lost
        for _ in range(2):
            t += 0.1
            assert outcomes(state.feed(c_record(velocity_kp=424), t)) == []
        assert state.take_outbox().endswith(b"{5:4242}{Q:P}"), "the set is sent again"
    t += 0.1
    assert outcomes(state.feed(c_record(velocity_kp=4242), t)) == []
    [done] = outcomes(state.feed(c_record(velocity_kp=4242), t + 0.1))
    assert isinstance(done, QueryDone) and done.text == "velocity_kp = 4242 (verified)"


def test_a_reply_to_a_read_sent_before_the_set_was_sent_again_is_not_a_vote() -> None:
    """A late reply made the host send the set again while a read was still on its way;
    once the set is sent again after a mismatch, that read's answer shows the board
    before it: not a vote (it would make the link look noisy and the set need 4 more)."""
    state = HostState()
    state.feed(c_record(), 0.0)
    state.start_query(ParamQuery((5, 4242), tries=10), 0.0)
    assert state.take_outbox() == b"{5:4242}{Q:P}"  # read 1
    state.tick(0.6)  # no reply in time: sent again (read 2)
    assert state.take_outbox() == b"{5:4242}{Q:P}"
    state.feed(c_record(velocity_kp=424), 0.65)  # read 1's reply, late: vote 1, read 3
    state.feed(c_record(velocity_kp=424), 0.7)  # read 2's: vote 2, the set is sent again
    assert state.take_outbox() == b"{Q:P}{5:4242}{Q:P}"
    assert outcomes(state.feed(c_record(velocity_kp=424), 0.75)) == []  # read 3's: old
    assert outcomes(state.feed(c_record(velocity_kp=4242), 0.8)) == []
    [done] = outcomes(state.feed(c_record(velocity_kp=4242), 0.9))
    assert isinstance(done, QueryDone) and done.text == "velocity_kp = 4242 (verified)"


A_RECORD = b"{A1:2:3:4}$"
GARBLED_A = b"{A1:2\r:3:4}$"  # an A record a noisy link damaged


def test_a_garbled_record_of_any_kind_during_a_read_makes_two_votes_not_enough() -> None:
    """The first two C records of a read can lose the same digit (§3.3) before any C
    record comes garbled, while the A and B records around them already show the noise.
    The same link carries the C records: a garbled record of any kind means a value
    needs NOISY_LEAD."""
    state = HostState()
    state.start_query(ParamQuery(), 0.0)
    wrong = c_record(max_position=1000)  # 10000 with a zero lost
    assert outcomes(state.feed(wrong, 0.1)) == []
    state.feed(GARBLED_A, 0.15)
    assert outcomes(state.feed(wrong, 0.2)) == [], "two agreeing votes on a noisy link"
    for i in range(NOISY_LEAD + 1):
        assert outcomes(state.feed(c_record(), 0.3 + 0.1 * i)) == []
    [done] = outcomes(state.feed(c_record(), 1.0))  # leads 1000 by NOISY_LEAD
    assert isinstance(done, QueryDone) and done.values[1] == 10000


def test_a_read_begun_on_a_link_that_garbled_a_record_lately_needs_the_noisy_lead() -> None:
    state = HostState()
    state.feed(A_RECORD + GARBLED_A, 0.0)
    state.start_query(ParamQuery(), 1.0)
    for t in (1.1, 1.2):
        assert outcomes(state.feed(c_record(max_position=1000), t)) == []


def test_what_a_port_that_is_no_board_sends_does_not_make_a_read_wait_longer() -> None:
    """Garbage before any record (an echo of `{Q:P}`, another program's port) is not a
    noisy board: the read fails after `tries` × 2 requests, not × NOISY_LEAD."""
    state = HostState()
    state.start_query(ParamQuery(tries=2, timeout=0.2), 0.0)
    t, failed = 0.0, None
    while failed is None:
        state.feed(state.take_outbox(), t)  # a loop: what is sent comes back
        t += 0.25
        failed = state.tick(t)
    assert isinstance(failed, QueryFailed) and "sent {Q:P} 4 times" in failed.text


def test_a_read_on_a_link_clean_for_a_while_still_settles_on_two_votes() -> None:
    state = HostState()
    state.feed(A_RECORD + GARBLED_A, 0.0)
    state.start_query(ParamQuery(), 10.0)  # the garbled record is past DEGRADED_WINDOW
    assert outcomes(state.feed(c_record(), 10.1)) == []
    [done] = outcomes(state.feed(c_record(), 10.2))
    assert isinstance(done, QueryDone) and done.values == params.DEFAULTS
