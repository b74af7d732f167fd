"""docs/protocol.md §15: a WHEELTEC board's chassis port as the simulated board runs it —
status frames at 20 Hz, Flag_Stop through the boot, commanded velocities reached as each
kind can, the IMU and battery, the time-out, frames dropped silently."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from appmode.board.firmware import Board
from appmode.board.profiles import Profile, profile_named
from appmode.protocol import chassis
from appmode.protocol.twist import Twist

BOOT = 10.0


def board_of(name: str, **spec: object) -> Board:
    profile = profile_named(name)
    if spec:
        assert profile.file is not None and profile.file.chassis is not None
        file = profile.file._replace(chassis=profile.file.chassis._replace(**spec))
        profile = replace(profile, file=file)
    return Board(profile=profile)


def statuses(board: Board, now: float) -> list[chassis.Status]:
    """The status frames up to `now`, read every 0.5 s as a host does (a board polled
    once after a long stall catches up at once: docs/design.md)."""
    data = b""
    while (at := board.core.tick_ms / 1000 + board.core.boot + 0.5) < now:
        data += board.poll_ports(at)[2]
    data += board.poll_ports(now)[2]
    events = chassis.StatusDecoder().feed(data)
    assert all(isinstance(e, chassis.Status) for e in events), events
    return [e for e in events if isinstance(e, chassis.Status)]


def drive(board: Board, twist: Twist, start: float, seconds: float) -> chassis.Status:
    """Send `twist` every 0.1 s for `seconds` from `start`; the last status frame."""
    last = None
    for step in range(round(seconds * 10)):
        at = start + step / 10
        board.receive_chassis(chassis.command(twist), at)
        got = statuses(board, at + 0.1)
        last = got[-1] if got else last
    assert last is not None
    return last


def test_status_frames_come_every_50_ms_with_flag_stop_through_the_boot() -> None:
    board = board_of("wheeltec-mec")
    frames = statuses(board, 12.0)
    assert len(frames) == 240  # 20 Hz for 12 s
    assert all(f.flag_stop for f in frames[: round(BOOT * 20) - 1])
    assert not any(f.flag_stop for f in frames[round(BOOT * 20) :])
    assert all(f.gyro[2] == 0 and abs(f.acceleration[2] - 9.8) < 0.01 for f in frames)
    assert frames[-1].volts == pytest.approx(12.6, abs=0.01)


def test_frames_while_booting_are_ignored() -> None:
    board = board_of("wheeltec-mec")
    last = drive(board, Twist(0.3, 0, 0), 1.0, 2.0)
    assert last.flag_stop and last.twist.still
    assert any("ignored while booting" in note.text for note in board.take_notes())


@pytest.mark.parametrize(
    ("name", "asked", "reached"),
    [
        ("wheeltec-mec", Twist(0.3, 0.2, 0.5), Twist(0.3, 0.2, 0.5)),
        ("wheeltec-diff", Twist(0.3, 0.2, 0.5), Twist(0.3, 0.0, 0.5)),
        ("wheeltec-akm", Twist(0.3, 0.2, 0.5), Twist(0.3, 0.0, 0.5)),
        # an Ackermann car turns no tighter than its minimum radius, and not in place
        ("wheeltec-akm", Twist(0.35, 0, 2.0), Twist(0.35, 0.0, 1.0)),
        ("wheeltec-akm", Twist(0.0, 0, 1.0), Twist(0.0, 0.0, 0.0)),
    ],
)
def test_each_kind_reaches_what_it_can(name: str, asked: Twist, reached: Twist) -> None:
    last = drive(board_of(name), asked, BOOT, 2.0)
    got = last.twist
    assert (got.forward, got.left, got.turn) == pytest.approx(
        (reached.forward, reached.left, reached.turn), abs=0.005
    )
    # the gyro agrees with the turn the wheels report
    assert last.angular_velocity[2] == pytest.approx(got.turn, abs=0.002)


def test_the_f1_board_stops_a_second_after_the_last_frame() -> None:
    board = board_of("wheeltec-mec")
    drive(board, Twist(0.3, 0, 0), BOOT, 1.0)
    frames = statuses(board, BOOT + 2.3)  # the last frame at BOOT + 0.9
    moving = [f.twist.forward for f in frames]
    assert moving[0] == pytest.approx(0.3, abs=0.005)
    assert frames[-1].twist.forward < 0.05, "zeroed 1 s after the last frame, then slowing"


def test_a_board_without_a_time_out_keeps_its_last_velocity_for_good() -> None:
    board = board_of("wheeltec-mec", timeout_ms=0)
    drive(board, Twist(0.3, 0, 0), BOOT, 1.0)
    assert statuses(board, BOOT + 30.0)[-1].twist.forward == pytest.approx(0.3, abs=0.005)


def test_a_self_test_drives_slowly_forward_after_the_boot() -> None:
    board = board_of("wheeltec-diff", self_test_ms=2000)
    frames = statuses(board, BOOT + 1.0)
    assert frames[-1].twist.forward == pytest.approx(0.1, abs=0.005)
    assert statuses(board, BOOT + 3.0)[-1].twist.still


def test_bad_frames_are_dropped_without_a_word_on_the_wire() -> None:
    board = board_of("wheeltec-mec")
    good = chassis.command(Twist(0.3, 0, 0))
    bad_xor = bytearray(good)
    bad_xor[4] ^= 0x40
    bad_tail = good[:-1] + b"\x7c"
    statuses(board, BOOT)
    data = b""
    for at in range(20):
        board.receive_chassis(bytes(bad_xor) + bad_tail, BOOT + at / 10)
        data += board.poll_ports(BOOT + at / 10 + 0.1)[2]
    events = chassis.StatusDecoder().feed(data)
    assert len(events) == 40, "nothing but status frames, 20 a second"
    assert all(isinstance(e, chassis.Status) and e.twist.still for e in events)
    assert sum(note.level == "rejected" for note in board.take_notes()) >= 20


def test_the_battery_falls_as_the_car_drives() -> None:
    board = board_of("wheeltec-mec")
    start = statuses(board, BOOT)[-1].millivolts
    drive(board, Twist(1.0, 0, 1.0), BOOT, 60.0)
    assert statuses(board, BOOT + 60.1)[-1].millivolts < start


def test_acceleration_shows_speeding_up_forward() -> None:
    board = board_of("wheeltec-mec")
    board.receive_chassis(chassis.command(Twist(0.5, 0, 0)), BOOT)
    frames = statuses(board, BOOT + 0.1)
    assert frames[-1].acceleration[0] > 0.5  # m/s², forward


def test_no_profile_but_wheeltecs_has_a_chassis_port() -> None:
    sheet: Profile = profile_named("sheet")
    board = Board(profile=sheet)
    board.receive_chassis(chassis.command(Twist(0.3, 0, 0)), 1.0)
    assert board.poll_ports(5.0)[2] == b""
    assert math.isinf(board.next_sends()[2])


def test_the_imu_axes_are_the_profiles_remap_of_the_chip() -> None:
    """F1 sends x = the chip's y, y = −the chip's x: the body's forward and left; a board
    with no remap (`x,y,z`) sends the chip's own axes, forward on its y."""
    for axes, forward_on in (("y,-x,z", 0), ("x,y,z", 1)):
        board = board_of("wheeltec-mec", imu_axes=axes)
        board.receive_chassis(chassis.command(Twist(0.5, 0, 0.5)), BOOT)
        frame = statuses(board, BOOT + 0.1)[-1]
        assert frame.acceleration[forward_on] > 0.5
        assert abs(frame.acceleration[1 - forward_on]) < 0.01
        assert frame.angular_velocity[2] > 0.1, "z is z on both"
