"""docs/protocol.md §3: the board→host records, encoded and decoded."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from appmode.protocol import params
from appmode.protocol.app import (
    Attitude,
    Garbage,
    Malformed,
    OtherRecord,
    ParamsRecord,
    Velocity,
    encode,
)
from appmode.protocol.app_decoders import BoardDecoder
from appmode.protocol.render import out_of_range, to_json
from tests.support.decoders import assert_any_bytes_ok, assert_split_invariant, decode_whole

C_DEFAULT = b"{C500:10000:20:0:10:10:10:0:0}$"


def test_s3_1_a_record_motion() -> None:
    assert encode(Velocity(12, -500, 3, 0)) == b"{A12:-500:3:0}$"
    assert decode_whole(BoardDecoder, b"{A12:-500:3:0}$") == [Velocity(12, -500, 3, 0)]


def test_s3_2_b_record_attitude_and_battery() -> None:
    assert encode(Attitude(-5, 0, 180, 87)) == b"{B-5:0:180:87}$"
    assert decode_whole(BoardDecoder, b"{B-5:0:-179:87}$") == [Attitude(-5, 0, -179, 87)]


def test_s3_3_c_record_nine_parameters() -> None:
    record = ParamsRecord(params.DEFAULTS)
    assert encode(record) == C_DEFAULT
    [decoded] = decode_whole(BoardDecoder, C_DEFAULT)
    assert decoded == record and to_json(decoded)["max_position"] == 10000


def test_s3_3_c_record_with_wrong_count_is_malformed() -> None:
    [event] = decode_whole(BoardDecoder, b"{C1:2:3}$")
    assert isinstance(event, Malformed) and event.raw == b"{C1:2:3}$"


def test_s3_3_c_record_out_of_range_is_read_and_flagged() -> None:
    for raw, odd in (
        (b"{C70000:0:0:0:0:0:0:0:0}$", ("max_speed",)),
        (b"{C0:0:0:0:0:0:0:0:5}$", ("system_mode",)),
        (b"{C500:10000:4000000000:-25:10:10:10:0:0}$", ("position_ki",)),
    ):
        [event] = decode_whole(BoardDecoder, raw)
        assert isinstance(event, ParamsRecord) and event.raw == raw
        assert out_of_range(event.values) == odd


def test_s3_missing_dollar_is_tolerated() -> None:
    events = assert_split_invariant(BoardDecoder, b"{A1:2:3:0}{B0:0:0:50}$")
    assert events == [Velocity(1, 2, 3, 0), Attitude(0, 0, 0, 50)]
    assert not events[0].terminated and events[1].terminated
    [last] = decode_whole(BoardDecoder, b"{A1:2:3:0}")
    assert last == Velocity(1, 2, 3, 0)


def test_s3_resynchronise_at_next_brace_after_garbage() -> None:
    data = b"+DISC:SUCCESS\r\n{A1:2:3:0}$\x00\xff{B1:2:3:4}$"
    events = assert_split_invariant(BoardDecoder, data)
    assert events == [
        Garbage(b"+DISC:SUCCESS\r\n"),
        Velocity(1, 2, 3, 0),
        Garbage(b"\x00\xff"),
        Attitude(1, 2, 3, 4),
    ]


def test_s3_truncated_record_is_reported_and_next_one_decoded() -> None:
    events = assert_split_invariant(BoardDecoder, b"{A1:2{B1:2:3:4}$")
    assert isinstance(events[0], Malformed) and events[0].raw == b"{A1:2"
    assert events[1] == Attitude(1, 2, 3, 4)


@pytest.mark.parametrize(
    ("raw", "reason"),
    [
        (b"{A1:2:3}$", "3 fields, expected 4"),
        (b"{B1:2:3:4:5}$", "5 fields"),
        (b"{A1::3:0}$", "integers"),
        (b"{A+1:2:3:0}$", "integers"),
        (b"{A1:2:3:0 }$", "integers"),
        (b"{}$", "empty"),
        (b"{1:2}$", "letter"),
    ],
)
def test_s3_malformed_records_are_reported(raw: bytes, reason: str) -> None:
    [event] = decode_whole(BoardDecoder, raw)
    assert isinstance(event, Malformed) and reason in event.reason


def test_s3_unknown_letter_is_its_own_event() -> None:
    assert decode_whole(BoardDecoder, b"{D1:-2}$") == [OtherRecord("D", (1, -2))]
    assert encode(OtherRecord("D", (1, -2))) == b"{D1:-2}$"


def test_s3_unterminated_record_never_grows_the_buffer() -> None:
    decoder = BoardDecoder()
    events = decoder.feed(b"{A" + b"1" * 10_000)
    assert decoder.buffered <= BoardDecoder.LIMIT
    assert all(isinstance(e, (Malformed, Garbage)) for e in events)
    assert decoder.feed(b"{A0:0:0:0}$")[-1] == Velocity(0, 0, 0, 0)


def test_s3_long_garbage_is_reported_in_bounded_runs() -> None:
    events = assert_split_invariant(BoardDecoder, b"x" * 200 + b"{A0:0:0:0}$")
    assert [len(e.raw) for e in events] == [64, 64, 64, 8, 11]


def test_s3_a_run_of_braces_is_reported_in_bounded_runs_not_brace_by_brace() -> None:
    events = assert_split_invariant(BoardDecoder, b"x" + b"{" * 150 + b"{A0:0:0:0}$")
    assert [len(e.raw) for e in events] == [1, 64, 64, 22, 11]
    assert events[1] == Malformed(b"{" * 64, "64 records interrupted by '{'")
    assert events[-1] == Velocity(0, 0, 0, 0)
    assert decode_whole(BoardDecoder, b"{{A0:0:0:0}$")[0].reason == "record interrupted by '{'"


ints = st.integers(-(2**31), 2**31 - 1)
records = st.one_of(
    st.builds(Velocity, ints, ints, ints, st.just(0)),
    st.builds(Attitude, ints, ints, st.integers(-179, 180), st.integers(0, 100)),
    st.tuples(*[st.integers(p.minimum, p.maximum) for p in params.PARAMS])
    .filter(lambda v: params.values_error(v) is None)
    .map(ParamsRecord),
    st.builds(
        OtherRecord, st.sampled_from("DEFXYZabc"), st.lists(ints, min_size=1, max_size=6).map(tuple)
    ),
)


@given(st.lists(records, max_size=20))
def test_property_encode_decode_round_trip(items: list[object]) -> None:
    data = b"".join(encode(r) for r in items)  # type: ignore[arg-type]
    assert decode_whole(BoardDecoder, data) == items


@given(st.binary(max_size=400), st.lists(st.integers(1, 64), max_size=20))
def test_property_arbitrary_bytes_never_raise_and_stay_bounded(
    data: bytes, cuts: list[int]
) -> None:
    assert_any_bytes_ok(BoardDecoder, data, cuts)


@given(
    st.lists(
        st.one_of(records, st.binary(max_size=8).map(lambda b: b.replace(b"{", b""))), max_size=15
    )
)
def test_property_records_survive_surrounding_noise(parts: list[object]) -> None:
    """Noise without a `{` never costs a record: each is decoded intact, in order."""
    data = b"".join(p if isinstance(p, bytes) else encode(p) for p in parts)  # type: ignore[arg-type]
    events = decode_whole(BoardDecoder, data)
    sent = [p for p in parts if not isinstance(p, bytes)]
    assert [e for e in events if not isinstance(e, (Garbage, Malformed))] == sent


def test_a_profile_s_field_counts_decode_alike_however_split() -> None:
    """Issue 53: a balance car's B record has three fields; a user's C record fewer than
    nine; a probe takes any count."""
    data = b"{A1:2:95:3}${B3:-4:5}$##${C42:100}${B1:2:3:4}$"
    events = assert_split_invariant(lambda: BoardDecoder(3, 2), data)
    kinds = [type(e).__name__ for e in events]
    assert kinds == ["Velocity", "OtherRecord", "Garbage", "ParamsRecord", "Malformed"]
    assert events[1].values == (3, -4, 5) and events[3].values == (42, 100)
    assert events[4].reason == "B record has 4 fields, expected 3"
    probe = assert_split_invariant(lambda: BoardDecoder(None), data)
    assert [type(e).__name__ for e in probe] == [
        "Velocity", "OtherRecord", "Garbage", "OtherRecord", "Attitude"
    ]  # fmt: skip
