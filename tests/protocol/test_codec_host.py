"""docs/protocol.md §2: the host→board stream, encoded and decoded."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from appmode.protocol import params
from appmode.protocol.app import (
    MAX_FRAME,
    BadFrame,
    Move,
    Noise,
    ReadParams,
    SaveParams,
    SetParam,
    Stop,
    SwitchPage,
    encode,
)
from appmode.protocol.app_decoders import HostDecoder
from tests.support.decoders import assert_any_bytes_ok, assert_split_invariant, decode_whole


def test_s2_1_letters_a_to_h_drive_directions_1_to_8() -> None:
    for n, letter in enumerate("ABCDEFGH", start=1):
        assert encode(Move(n)) == letter.encode()
        assert decode_whole(HostDecoder, letter.encode()) == [Move(n)]


def test_s2_1_raw_bytes_1_to_8_are_directions() -> None:
    for n in range(1, 9):
        assert encode(Move(n, numeric=True)) == bytes([n])
        assert decode_whole(HostDecoder, bytes([n])) == [Move(n, numeric=True)]


def test_s2_1_page_letters_and_stop() -> None:
    assert decode_whole(HostDecoder, b"IJKZ") == [
        SwitchPage("I"),
        SwitchPage("J"),
        SwitchPage("K"),
        Stop(),
    ]
    assert encode(SwitchPage("K")) == b"K"
    assert encode(Stop()) == b"Z"


def test_s2_1_every_other_byte_is_noise() -> None:
    known = set(b"ABCDEFGHIJKZ{") | set(range(1, 9))
    for value in range(256):
        if value in known:
            continue
        assert decode_whole(HostDecoder, bytes([value])) == [Noise(bytes([value]))]


def test_s2_2_read_and_save_frames_use_the_ascii_column() -> None:
    assert encode(ReadParams()) == bytes.fromhex("7B 51 3A 50 7D")
    assert encode(SaveParams()) == bytes.fromhex("7B 51 3A 57 7D")
    assert decode_whole(HostDecoder, b"{Q:P}{Q:W}") == [ReadParams(), SaveParams()]


def test_s2_2_q_frame_with_any_separator_is_accepted_with_a_warning() -> None:
    [read] = decode_whole(HostDecoder, bytes.fromhex("7B 51 03 50 7D"))
    assert isinstance(read, ReadParams) and read.separator == 0x03
    assert read.warning is not None and "0x03" in read.warning
    [save] = decode_whole(HostDecoder, b"{Q;W}")
    assert isinstance(save, SaveParams) and save.warning is not None
    assert ReadParams().warning is None


@pytest.mark.parametrize("param", params.PARAMS, ids=lambda p: p.name)
def test_s2_2_set_frame_for_each_parameter(param: params.Param) -> None:
    for value in (0, param.default, 3):
        data = b"{%d:%d}" % (param.index, value)
        assert encode(SetParam(param.index, value)) == data
        assert decode_whole(HostDecoder, data) == [SetParam(param.index, value)]
    top = param.maximum if param.index != params.SYSTEM_MODE else 0xFFF3
    assert decode_whole(HostDecoder, b"{%d:%d}" % (param.index, top)) == [
        SetParam(param.index, top)
    ]


@pytest.mark.parametrize(
    ("frame", "reason"),
    [
        (b"{0:}", "no value"),
        (b"{0:-5}", "not digits"),
        (b"{0:5a}", "not digits"),
        (b"{0: 5}", "not digits"),
        (b"{0:65536}", "max_speed (parameter 0) must be in 0–65535"),
        (b"{2:4294967296}", "position_kp"),
        (b"{8:4}", "drive type 4"),
        (b"{8:65535}", "drive type 7"),
        (b"{9:1}", "no parameter 9"),
        (b"{}", "unknown frame"),
        (b"{Q:X}", "unknown frame"),
        (b"{hello}", "unknown frame"),
    ],
)
def test_s2_2_bad_set_frames_are_reported_not_applied(frame: bytes, reason: str) -> None:
    [event] = decode_whole(HostDecoder, frame)
    assert isinstance(event, BadFrame) and reason in event.reason and event.raw == frame


def test_s2_2_encode_rejects_out_of_range_naming_the_parameter() -> None:
    with pytest.raises(ValueError, match=r"velocity_kp \(parameter 5\) must be in 0–4294967295"):
        encode(SetParam(5, 2**32))
    with pytest.raises(ValueError, match="drive type"):
        encode(SetParam(8, 6))
    with pytest.raises(ValueError, match="direction"):
        encode(Move(9))


def test_s2_2_frame_of_exactly_50_bytes_is_accepted() -> None:
    frame = b"{1:" + b"0" * (MAX_FRAME - 5) + b"7}"
    assert len(frame) == MAX_FRAME
    assert decode_whole(HostDecoder, frame) == [SetParam(1, 7)]


def test_s2_2_over_long_frame_is_discarded_whole_and_reported() -> None:
    frame = b"{1:" + b"0" * MAX_FRAME + b"7}"
    events = assert_split_invariant(HostDecoder, frame + b"A")
    assert all(isinstance(e, BadFrame) and "over-long" in e.reason for e in events[:-1])
    assert events[-1] == Move(1)
    assert "discarded" in events[-2].reason


def test_s2_2_a_brace_ends_an_over_long_frame_also_where_a_whole_frame_follows() -> None:
    """The `{` that cuts an over-long frame at its 51st byte starts a frame that is read;
    a `}` after that frame is noise, not the over-long frame's end (whole, the decoder
    took it for that; split, it did not: found by fuzz/fuzz_decoders.py)."""
    events = assert_split_invariant(HostDecoder, b"{" + b"x" * 49 + b"{Q:P}}A")
    assert [type(e) for e in events] == [BadFrame, ReadParams, Noise, Move]


def test_s2_2_over_long_garbage_never_grows_the_buffer() -> None:
    decoder = HostDecoder()
    events = decoder.feed(b"{" + b"x" * 100_000)
    assert decoder.buffered <= HostDecoder.LIMIT
    assert sum(len(e.raw) for e in events) + decoder.buffered == 100_001
    assert decoder.feed(b"}Z")[-1] == Stop()


def test_s2_2_brace_inside_a_frame_restarts_the_frame() -> None:
    events = assert_split_invariant(HostDecoder, b"{0:8{1:9}")
    assert isinstance(events[0], BadFrame) and events[0].raw == b"{0:8"
    assert events[1] == SetParam(1, 9)


def test_s2_2_a_run_of_braces_is_reported_in_bounded_runs_not_brace_by_brace() -> None:
    events = assert_split_invariant(HostDecoder, b"A" + b"{" * 70 + b"{Q:P}")
    assert [len(e.raw) for e in events] == [1, 64, 6, 5]
    assert events[1] == BadFrame(b"{" * 64, "64 frames interrupted by '{'")
    assert events[-1] == ReadParams()


def test_stream_is_split_invariant() -> None:
    data = b"JA\x01{Q:P}xx{0:800}{8:5}B{Q\x03W}Z{0:" + b"9" * 60 + b"}K{1:2"
    events = assert_split_invariant(HostDecoder, data)
    assert isinstance(events[-1], BadFrame) and "unterminated" in events[-1].reason


commands = st.one_of(
    st.builds(Move, st.integers(1, 8), st.booleans()),
    st.just(Stop()),
    st.sampled_from("IJK").map(SwitchPage),
    st.just(ReadParams()),
    st.just(SaveParams()),
    st.sampled_from(params.PARAMS)
    .flatmap(lambda p: st.integers(p.minimum, p.maximum).map(lambda v: SetParam(p.index, v)))
    .filter(lambda c: params.value_error(c.index, c.value) is None),
)


@given(st.lists(commands, max_size=20))
def test_property_encode_decode_round_trip(cmds: list[object]) -> None:
    data = b"".join(encode(c) for c in cmds)  # type: ignore[arg-type]
    assert decode_whole(HostDecoder, data) == cmds


@given(st.binary(max_size=400), st.lists(st.integers(1, 64), max_size=20))
def test_property_arbitrary_bytes_never_raise_and_stay_bounded(
    data: bytes, cuts: list[int]
) -> None:
    assert_any_bytes_ok(HostDecoder, data, cuts)
