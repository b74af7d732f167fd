"""docs/protocol.md §8–§12: the control port's binary frames, replies and reports."""

from __future__ import annotations

import random
import time
from functools import partial

import pytest
from hypothesis import given
from hypothesis import strategies as st

from appmode.protocol import control, settings
from appmode.protocol.control import (
    BadFrame,
    EncoderReport,
    Garbage,
    MotorFrame,
    PositionFrame,
    Reply,
    SetSetting,
    Status,
    StoreFrame,
    VelocityFrame,
    encode,
)
from appmode.protocol.control_decoders import FrameDecoder, ReplyDecoder
from appmode.protocol.params import DriveType
from tests.support.decoders import assert_any_bytes_ok, assert_split_invariant, decode_whole

MAX_SPEED = settings.BY_NAME["max_speed"]


def hexes(text: str) -> bytes:
    return bytes.fromhex(text)


def test_s8_2_every_frame_opens_with_ff_fe_and_its_mode() -> None:
    frames = [
        control.velocity(DriveType.OMNI, 1, 2, 3),
        MotorFrame((1, 2, 3)),
        PositionFrame(1, 2, 3),
        control.read("max_speed"),
    ]
    for frame, mode in zip(frames, (0x01, 0x02, 0x03, 0x80), strict=True):
        raw = encode(frame)
        assert raw[:3] == bytes([0xFF, 0xFE, mode]) and len(raw) == 10


def test_s8_2_a_value_holding_ff_fe_does_not_split_the_frame() -> None:
    frame = VelocityFrame(0xFFFE, 0xFFFE, 0xFFFE)
    raw = encode(frame)
    assert raw.count(control.HEADER) == 4
    assert assert_split_invariant(FrameDecoder, raw) == [frame]


def test_s8_2_unknown_mode_is_three_bytes_of_garbage_then_resync() -> None:
    velocity = encode(control.velocity(DriveType.OMNI, y=5))
    events = assert_split_invariant(FrameDecoder, hexes("FF FE 07") + velocity)
    assert events == [Garbage(hexes("FF FE 07"), "unknown mode 07"), VelocityFrame(0, 5, 0)]


def test_s8_2_bytes_outside_frames_are_reported_not_dropped() -> None:
    velocity = encode(control.velocity(DriveType.OMNI, y=5))
    events = assert_split_invariant(FrameDecoder, b"noise\xff" + velocity + b"\xfe")
    assert [type(e) for e in events] == [Garbage, VelocityFrame, Garbage]
    assert events[0].raw == b"noise\xff"


def test_s8_2_a_truncated_frame_at_the_end_is_reported() -> None:
    velocity = encode(control.velocity(DriveType.OMNI, y=5))
    assert decode_whole(FrameDecoder, velocity[:7]) == [
        Garbage(velocity[:7], "truncated frame at end of stream")
    ]


def test_s8_2_the_motor_frame_length_follows_the_drive_type() -> None:
    three = encode(MotorFrame((100, -200, 300)))
    four = encode(MotorFrame((100, -200, 300, -400)))
    assert len(three) == 10 and len(four) == 12
    assert decode_whole(FrameDecoder, three) == [MotorFrame((100, -200, 300))]
    for drive in (DriveType.MECANUM, DriveType.DIFF, DriveType.DIFF_GYRO):
        make = partial(FrameDecoder, drive)
        assert assert_split_invariant(make, four) == [MotorFrame((100, -200, 300, -400))]


def test_s8_3_the_stop_frame_is_a_velocity_of_zeros() -> None:
    assert hexes("FF FE 01 00 00 00 00 00 00 00") == control.STOP
    assert encode(control.velocity(DriveType.OMNI)) == control.STOP


def test_s9_1_velocity_direction_bits_x2_y1_z0() -> None:
    assert encode(control.velocity(DriveType.MECANUM, -1, 2, -3)) == hexes(
        "FF FE 01 00 01 00 02 00 03 05"
    )
    assert decode_whole(FrameDecoder, hexes("FF FE 01 01 F4 00 C8 00 64 07")) == [
        VelocityFrame(-500, -200, -100)
    ]


def test_s9_1_angle_mode_sets_bit_4_and_carries_the_angle_in_tenths() -> None:
    frame = control.velocity(DriveType.OMNI, angle=-900)
    assert encode(frame) == hexes("FF FE 01 00 00 00 00 03 84 11")
    assert decode_whole(FrameDecoder, encode(frame)) == [VelocityFrame(0, 0, -900, angle=True)]


def test_s9_1_diff_takes_duties_and_diff_gyro_left_and_right() -> None:
    assert control.velocity(DriveType.DIFF, y=1000, z=-5).values == (0, 1000, -5)
    assert control.velocity(DriveType.DIFF_GYRO, left=-300, right=700).values == (-300, 700, 0)
    with pytest.raises(ValueError, match=r"y must be in −1000…1000, not 1001"):
        control.velocity(DriveType.DIFF, y=1001)
    with pytest.raises(ValueError, match="left and right"):
        control.velocity(DriveType.DIFF_GYRO, y=1)
    with pytest.raises(ValueError, match="no x"):
        control.velocity(DriveType.DIFF, x=1)
    with pytest.raises(ValueError, match=r"x must be in −65535…65535, not 70000"):
        control.velocity(DriveType.OMNI, x=70000)


def test_s9_2_motor_bits_four_motors_bit_3_is_motor_4() -> None:
    raw = encode(MotorFrame((1, 2, 3, -4)))
    assert raw == hexes("FF FE 02 00 01 00 02 00 03 00 04 08")
    assert encode(MotorFrame((-1, 2, 3))) == hexes("FF FE 02 00 01 00 02 00 03 04")


def test_s9_3_position_frame() -> None:
    raw = encode(PositionFrame(100, -200, 0))
    assert raw == hexes("FF FE 03 00 64 00 C8 00 00 02")
    assert decode_whole(FrameDecoder, raw) == [PositionFrame(100, -200, 0)]


@pytest.mark.parametrize("setting", settings.SETTINGS, ids=lambda s: s.name)
def test_s10_every_setting_encodes_and_decodes(setting: settings.Setting) -> None:
    value = min(setting.maximum, 1234)
    raw = encode(SetSetting(setting, value))
    assert raw == hexes(f"FF FE 80 80 {setting.id:02X}") + value.to_bytes(4, "big") + b"\0"
    assert decode_whole(FrameDecoder, raw) == [SetSetting(setting, value)]


def test_s10_out_of_range_values_raise_and_decode_as_bad_frames() -> None:
    with pytest.raises(ValueError, match=r"max_speed \(setting 01\) must be in 0–65535"):
        encode(SetSetting(MAX_SPEED, 65536))
    with pytest.raises(ValueError, match="drive type 5"):
        encode(SetSetting(settings.BY_NAME["system_mode"], 5))
    raw = hexes("FF FE 80 80 01 00 01 00 00 00")
    [event] = decode_whole(FrameDecoder, raw)
    assert isinstance(event, BadFrame) and "must be in 0–65535, not 65536" in event.reason


def test_s10_load_defaults_save() -> None:
    for name, code in (("load", 1), ("defaults", 2), ("save", 3)):
        raw = encode(control.store(name))
        assert raw == hexes(f"FF FE 80 80 00 80 00 00 {code:02X} 00")
        assert decode_whole(FrameDecoder, raw) == [StoreFrame(settings.STORE_BY_NAME[name])]
    [bad] = decode_whole(FrameDecoder, hexes("FF FE 80 80 00 80 00 00 04 00"))
    assert isinstance(bad, BadFrame)


def test_s11_reads_and_their_reply_ids() -> None:
    assert encode(control.read("max_speed")) == hexes("FF FE 80 80 11 00 00 00 00 00")
    assert settings.read_named("position_ki").reply_id == 0x04  # the sheet's 2C-4 slip
    assert settings.read_named("gyro_calibration").ss == 0x1A
    assert settings.read_named("pending_angle").reply_id == 0x20
    assert [settings.read_named(f"speed_{w}").ss for w in "abcd"] == [0x21, 0x22, 0x23, 0x24]
    assert [settings.read_named(f"position_{w}").ss for w in "abcd"] == [0x25, 0x26, 0x27, 0x28]
    [unknown] = decode_whole(FrameDecoder, hexes("FF FE 80 80 30 00 00 00 00 00"))
    assert isinstance(unknown, BadFrame) and "SS 30" in unknown.reason


def test_s11_replies_unsigned_for_settings_signed_for_encoders() -> None:
    data = hexes("23 01 00 00 01 F4 23 21 FF FF FF 9C 23 20 FF FF FC 7C")
    events = assert_split_invariant(ReplyDecoder, data)
    assert [(e.name, e.value) for e in events] == [
        ("max_speed", 500),
        ("speed_a", -100),
        ("pending_angle", -900),
    ]
    assert encode(Reply(0x21, -100)) == hexes("23 21 FF FF FF 9C")


def test_s12_encoder_report_34_bytes_or_26_on_an_omni() -> None:
    four = EncoderReport((1, 2, 3, 4), (-1, -2, -3, -4))
    three = EncoderReport((1, 2, 3), (-1, -2, -3))
    assert len(encode(four)) == 34 and len(encode(three)) == 26
    assert encode(four)[0] == 0x24 and encode(four)[-1] == 0x19
    assert assert_split_invariant(ReplyDecoder, encode(four)) == [four]
    assert assert_split_invariant(partial(ReplyDecoder, 3), encode(three)) == [three]


def test_s12_encoder_report_bytes_and_its_range() -> None:
    """Each speed signed 32-bit big-endian, target then actual per wheel; beyond 32 bits
    a ValueError that says so."""
    report = EncoderReport((1, -2, 2**31 - 1), (-(2**31), 5, 0))
    assert encode(report) == hexes(
        "24 00000001 80000000 FFFFFFFE 00000005 7FFFFFFF 00000000 19".replace(" ", "")
    )
    with pytest.raises(ValueError, match="signed 32-bit"):
        encode(EncoderReport((2**31, 0, 0), (0, 0, 0)))


def test_s12_a_report_without_its_end_byte_is_garbage() -> None:
    bad = encode(EncoderReport((1, 2, 3, 4), (5, 6, 7, 8)))[:-1] + b"\x00"
    events = decode_whole(ReplyDecoder, bad + encode(Reply(1, 500)))
    assert events[-1] == Reply(1, 500)
    assert all(isinstance(e, Garbage) for e in events[:-1])
    assert b"".join(e.raw for e in events) == bad + encode(Reply(1, 500))


def test_s12_app_mode_decodes_app_records() -> None:
    decoder = ReplyDecoder(app_mode=True)
    [record] = decoder.feed(b"{A0:200:0:100}$")
    assert (record.x, record.y) == (0, 200)
    assert decoder.set_app_mode(False) == []
    assert decoder.feed(encode(Reply(1, 7))) == [Reply(1, 7)]


@given(st.binary(max_size=200), st.lists(st.integers(1, 40), max_size=10))
def test_host_decoder_never_raises_bounded_and_every_byte_in_one_event(
    data: bytes, cuts: list[int]
) -> None:
    data = data + encode(control.velocity(DriveType.OMNI, 1, 2, 3)) + data
    assert_any_bytes_ok(partial(FrameDecoder, DriveType.MECANUM), data, cuts)


@given(st.binary(max_size=200), st.lists(st.integers(1, 40), max_size=10))
def test_board_decoder_never_raises_bounded_and_every_byte_in_one_event(
    data: bytes, cuts: list[int]
) -> None:
    assert_any_bytes_ok(ReplyDecoder, data, cuts, ReplyDecoder().limit)


@pytest.mark.parametrize(
    "data",
    [
        random.Random(7).randbytes(1_000_000),
        b"\xff" * 1_000_000,
        b"\xff\xfe" * 500_000,
        b"#" * 1_000_000,
        b"$" * 1_000_000,
    ],
    ids=["random", "ff", "headers", "hashes", "dollars"],
)
def test_a_megabyte_of_garbage_decodes_in_linear_time(data: bytes) -> None:
    for make in (FrameDecoder, ReplyDecoder):
        start = time.perf_counter()
        decoder = make()
        events = [*decoder.feed(data), *decoder.flush()]
        assert b"".join(e.raw for e in events) == data
        assert time.perf_counter() - start < 20.0


def test_a_run_of_ff_is_garbage_in_bounded_runs_and_its_last_ff_may_start_a_burst() -> None:
    tail = b"\xff\x00\x00" + encode(Reply(1, 5))
    events = assert_split_invariant(ReplyDecoder, b"\xff" * 69 + tail)
    assert [len(e.raw) for e in events] == [64, 5, 3, 6]
    assert [type(e) for e in events] == [Garbage, Garbage, Status, Reply]
    assert decode_whole(ReplyDecoder, b"\xff" * 3)[-1] == Status(b"\xff")


def test_a_flood_of_24_is_garbage_in_bounded_runs_and_a_report_after_it_decodes() -> None:
    report = EncoderReport((1, 2, 3, 4), (5, 6, 7, 8))
    events = assert_split_invariant(ReplyDecoder, b"$" * 100 + encode(report))
    assert events[-1] == report
    assert all(isinstance(e, Garbage) and len(e.raw) <= 64 for e in events[:-1])


protocol_bytes = st.lists(st.sampled_from(b"\xff\xfe\x24\x23\x19\x00"), max_size=300).map(bytes)


@given(protocol_bytes, st.lists(st.integers(1, 40), min_size=1, max_size=20))
def test_runs_of_the_protocols_own_bytes_keep_every_byte_in_one_event(
    data: bytes, cuts: list[int]
) -> None:
    for wheels in (4, 3, None):
        make = partial(ReplyDecoder, wheels)
        assert_any_bytes_ok(make, data, cuts, limit=ReplyDecoder(wheels).limit)


@pytest.mark.parametrize("wheels", [3, 4])
def test_s12_a_report_of_either_length_decodes_without_its_wheel_count(wheels: int) -> None:
    report = EncoderReport(tuple(range(-wheels, 0)), tuple(range(100, 100 + wheels)))
    data = encode(report) + encode(Reply(1, 500)) + encode(report)
    events = assert_split_invariant(partial(ReplyDecoder, None), data)
    assert [type(e) for e in events] == [EncoderReport, Reply, EncoderReport]
    assert events[0].targets == report.targets and events[2].actuals == report.actuals


@given(st.binary(max_size=300), st.lists(st.integers(1, 40), min_size=1, max_size=20))
def test_the_report_length_finder_keeps_every_byte_in_one_event(
    data: bytes, cuts: list[int]
) -> None:
    assert_any_bytes_ok(partial(ReplyDecoder, None), data, cuts, limit=ReplyDecoder(None).limit)


@pytest.mark.parametrize(
    ("sent", "rest"),
    [
        ("", ""),
        ("12 34", ""),
        ("FF FE", "01 00 00 00 00 00 00 00"),
        ("FF FE 01 03", "00 00 00 00 00 00"),
        ("FF FE 80 80 11", "00 00 00 00 00"),
    ],
)
def test_rest_completes_an_open_frame_so_the_next_is_read_whole(sent: str, rest: str) -> None:
    decoder = FrameDecoder(DriveType.MECANUM)
    decoder.feed(bytes.fromhex(sent))
    assert decoder.rest() == bytes.fromhex(rest)
    after = decoder.feed(decoder.rest() + control.STOP)
    assert after[-1] == control.VelocityFrame(0, 0, 0), "the stop frame is read whole"
