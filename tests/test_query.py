"""Parameter reads and verified sets as a state machine (client.HostState + query)."""

from __future__ import annotations

import pytest

from appmode import params
from appmode.client import HostState
from appmode.protocol import ParamsRecord, encode
from appmode.query import ParamQuery, QueryDone, QueryFailed


def c_record(**changes: int) -> bytes:
    values = list(params.DEFAULTS)
    for name, value in changes.items():
        values[params.BY_NAME[name].index] = value
    return encode(ParamsRecord(tuple(values)))


def test_read_sends_q_p_and_ends_on_a_c_record() -> None:
    state = HostState()
    state.start_query(ParamQuery(), 0.0)
    assert state.take_outbox() == b"{Q:P}"
    events = state.feed(c_record(), 0.1)
    assert isinstance(events[-1], QueryDone) and events[-1].values == params.DEFAULTS
    assert state.query is None


def test_read_resends_on_timeout_then_fails_with_a_clear_error() -> None:
    state = HostState()
    state.start_query(ParamQuery(timeout=0.5, tries=3, where="/dev/ttyUSB0"), 0.0)
    state.take_outbox()
    assert state.tick(0.4) is None and state.take_outbox() == b""
    assert state.tick(0.5) is None and state.take_outbox() == b"{Q:P}"
    assert state.tick(1.0) is None and state.take_outbox() == b"{Q:P}"
    outcome = state.tick(1.5)
    assert isinstance(outcome, QueryFailed)
    assert "no parameters from /dev/ttyUSB0: sent {Q:P} 3 times" in outcome.text


def test_set_is_verified_by_the_c_record_read_after_it() -> None:
    state = HostState()
    state.start_query(ParamQuery((0, 800)), 0.0)
    assert state.take_outbox() == b"{0:800}{Q:P}"
    stale = state.feed(c_record(), 0.02)  # a C record already on its way: old value
    assert not any(isinstance(e, (QueryDone, QueryFailed)) for e in stale)
    done = state.feed(c_record(max_speed=800), 0.1)
    assert isinstance(done[-1], QueryDone) and done[-1].text == "max_speed = 800 (verified)"


def test_set_that_never_takes_fails_naming_the_value_read() -> None:
    state = HostState()
    state.start_query(ParamQuery((5, 42), timeout=0.5, tries=2), 0.0)
    assert state.take_outbox() == b"{5:42}{Q:P}"
    state.feed(c_record(), 0.1)
    state.tick(0.5)
    assert state.take_outbox() == b"{5:42}{Q:P}"
    state.feed(c_record(), 0.6)
    outcome = state.tick(1.0)
    assert isinstance(outcome, QueryFailed)
    assert outcome.text.startswith("velocity_kp reads 10 after setting it to 42 2 times")


def test_a_corrupted_c_record_never_completes_a_query() -> None:
    state = HostState()
    state.start_query(ParamQuery(), 0.0)
    events = state.feed(b"{C500:10000:20:0:1\x000:10:10:0:0}$", 0.1)
    assert not any(isinstance(e, QueryDone) for e in events)
    assert state.stats.errors == 1 and state.params is None


def test_query_rejects_out_of_range_before_sending() -> None:
    with pytest.raises(ValueError, match="max_speed"):
        ParamQuery((0, 70000))
