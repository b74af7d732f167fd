"""docs/protocol.md §15: the chassis port's frames, both ways, and their decoders on bad
input (junk between frames, frames cut across reads, wrong XORs, 7B inside data)."""

from __future__ import annotations

import struct

from hypothesis import given
from hypothesis import strategies as st

from appmode.protocol import chassis
from appmode.protocol.twist import Twist


def vendor_frame(vx: float, vy: float, wz: float) -> bytes:
    """A command frame as the vendor's driver builds it (the shared file's table):
    header, mode, reserved, three int16 big-endian ×1000, XOR of bytes 0–8, tail."""
    body = bytes([0x7B, 0, 0]) + struct.pack(">hhh", int(vx * 1000), int(vy * 1000), int(wz * 1000))
    check = 0
    for byte in body:
        check ^= byte
    return body + bytes([check, 0x7D])


def test_a_command_frame_is_the_vendor_drivers() -> None:
    assert chassis.command(Twist(0.3, -0.1, 0.5)) == vendor_frame(0.3, -0.1, 0.5)
    assert vendor_frame(0, 0, 0) == chassis.STOP
    assert chassis.command(Twist(0.3, 0, 0.5)).hex(" ") == "7b 00 00 01 2c 00 00 01 f4 a3 7d"


def test_a_velocity_past_the_int16_is_clamped_not_wrapped() -> None:
    """The vendor's driver truncates to int16: 40 m/s would wrap to −25.5 m/s backward."""
    frame = chassis.CommandDecoder().feed(chassis.command(Twist(40.0, -40.0, 0.0)))[0]
    assert isinstance(frame, chassis.Command)
    assert (frame.vx, frame.vy) == (32767, -32767)


def test_a_status_frame_reads_in_si() -> None:
    raw = chassis.status(1, (300, -20, 500), (0, 1672, 16384), (0, 0, 1877), 11900)
    assert len(raw) == chassis.STATUS_LEN and raw[0] == 0x7B and raw[-1] == 0x7D
    (frame,) = chassis.StatusDecoder().feed(raw)
    assert isinstance(frame, chassis.Status)
    assert frame.flag_stop == 1
    assert frame.twist == Twist(0.3, -0.02, 0.5)
    assert abs(frame.acceleration[1] - 1.0) < 0.001 and abs(frame.acceleration[2] - 9.8) < 0.01
    assert abs(frame.angular_velocity[2] - 0.5001) < 0.001
    assert frame.volts == 11.9
    assert chassis.as_json(frame)["volts"] == 11.9


FRAMES = [chassis.status(0, (i, -i, 2 * i), (1, 2, 16384), (3, 4, 5), 12000 - i) for i in range(5)]


def events_of(data: bytes, cuts: list[int]) -> list[chassis.Event]:
    decoder = chassis.StatusDecoder()
    out: list[chassis.Event] = []
    at = 0
    for cut in [*sorted(cuts), len(data)]:
        out += decoder.feed(data[at:cut])
        at = cut
    return out + decoder.flush()


@given(st.lists(st.integers(0, 5 * chassis.STATUS_LEN), max_size=8))
def test_frames_cut_across_reads_read_whole(cuts: list[int]) -> None:
    data = b"".join(FRAMES)
    assert [e.raw for e in events_of(data, cuts)] == FRAMES


@given(st.binary(max_size=80), st.lists(st.integers(0, 400), max_size=6))
def test_every_byte_goes_to_exactly_one_event(junk: bytes, cuts: list[int]) -> None:
    data = junk + FRAMES[0] + junk + FRAMES[1]
    events = events_of(data, cuts)
    assert b"".join(e.raw for e in events) == data
    assert FRAMES[1] in [e.raw for e in events]


def test_junk_between_frames_is_named_and_the_frames_found_again() -> None:
    events = events_of(b"\x00\x7b\x7d" + FRAMES[0] + b"garbage" + FRAMES[1], [])
    kinds = [type(e).__name__ for e in events]
    assert kinds == ["Junk", "Status", "Junk", "Status"]
    assert events[0].raw == b"\x00\x7b\x7d"
    assert isinstance(events[0], chassis.Junk) and events[0].reason == chassis.OUTSIDE


def test_a_wrong_xor_is_no_frame_and_says_so() -> None:
    bad = bytearray(FRAMES[0])
    bad[5] ^= 0x01
    events = events_of(bytes(bad) + FRAMES[1], [])
    assert [e.raw for e in events if isinstance(e, chassis.Status)] == [FRAMES[1]]
    junk = [e for e in events if isinstance(e, chassis.Junk)]
    assert junk and "wrong XOR" in junk[0].reason


def test_a_7b_inside_a_frame_is_no_start() -> None:
    """A velocity of 0x7B00 (31.488 m/s) puts 7B in the data: the frame still reads
    whole, and a frame whose start was lost resynchronises at the next real one."""
    inside = chassis.status(0, (0x7B00, 0x7B7D, 0), (0x7B, 0, 0), (0, 0, 0), 12000)
    events = events_of(inside[7:] + inside + FRAMES[0], [])
    frames = [e.raw for e in events if isinstance(e, chassis.Status)]
    assert frames == [inside, FRAMES[0]]


def test_a_frame_cut_off_at_the_end_is_named() -> None:
    (event,) = events_of(FRAMES[0][:10], [])
    assert isinstance(event, chassis.Junk) and event.reason == "a frame cut off"


def test_a_decoder_holds_less_than_a_frame() -> None:
    decoder = chassis.StatusDecoder()
    for _ in range(100):
        events = decoder.feed(b"\x7b" * 1000 + b"\x00" * 10)
        assert sum(len(e.raw) for e in events) >= 1000 - chassis.STATUS_LEN
    held = decoder.flush()
    assert sum(len(e.raw) for e in held) < chassis.STATUS_LEN


def test_the_board_side_reads_command_frames() -> None:
    decoder = chassis.CommandDecoder()
    data = b"\x01" + chassis.command(Twist(-0.2, 0.1, -1.0), mode=3)
    events = decoder.feed(data[:4]) + decoder.feed(data[4:])
    assert isinstance(events[-1], chassis.Command)
    assert events[-1].twist == Twist(-0.2, 0.1, -1.0) and events[-1].mode == 3
    assert str(events[-1]).startswith("velocity -0.20 m/s")


def test_a_profiles_chassis_table_is_checked_a_line_a_mistake() -> None:
    from appmode.protocol.profile_file import ProfileError, parse

    text = (
        'name = "mine"\nlike = "wheeltec-mec"\n[chassis]\nkind = "tank"\ntimeout_ms = -1\n'
        'imu_axes = "x,x,z"\nspeed = 3\n'
    )
    try:
        parse(text, "mine.toml")
    except ProfileError as exc:
        problems = exc.problems
    else:
        raise AssertionError("a bad [chassis] table was taken")
    assert any("chassis.speed: unknown" in p for p in problems)
    assert any("chassis.kind = 'tank'" in p for p in problems)
    assert any("chassis.timeout_ms = -1" in p for p in problems)
    assert any("chassis.imu_axes = 'x,x,z'" in p for p in problems)
    good = parse('name = "mine"\nlike = "wheeltec-akm"\n[chassis]\nboot_ms = 500\n', "m.toml")
    assert good.chassis is not None
    assert (good.chassis.kind, good.chassis.boot_ms, good.chassis.min_radius) == ("akm", 500, 0.35)
