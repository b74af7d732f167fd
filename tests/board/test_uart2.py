"""docs/protocol.md §8–§12: the board's control port, one state with the APP port."""

from __future__ import annotations

from hypothesis import given
from hypothesis import settings as hypothesis_settings
from hypothesis import strategies as st

from appmode.board.firmware import Board
from appmode.board.profiles import MINIBALANCE, SHEET, Profile
from appmode.board.store import MemoryStore
from appmode.protocol import app, app_decoders, control, control_decoders, params, settings
from appmode.protocol.control import MotorFrame, PositionFrame, SetSetting, encode
from appmode.protocol.params import DriveType


def replies(board: Board, now: float) -> dict[str, int]:
    wheels = control.motor_count(board.drive_type)
    events = control_decoders.ReplyDecoder(wheels).feed(board.poll_uart2(now))
    return {e.name: e.value for e in events if isinstance(e, control.Reply)}


def read(board: Board, name: str, now: float) -> int:
    board.receive_uart2(encode(control.read(name)), now)
    return replies(board, now + 0.011)[name]


def a_records(board: Board, now: float) -> list[app.Velocity]:
    return [
        e for e in app_decoders.BoardDecoder().feed(board.poll(now)) if isinstance(e, app.Velocity)
    ]


def set_setting(board: Board, name: str, value: int, now: float) -> None:
    board.receive_uart2(encode(SetSetting(settings.BY_NAME[name], value)), now)


def test_s8_3_takeover_at_the_tenth_byte_any_bytes() -> None:
    board = Board()
    board.receive(b"A", 0.0)
    board.receive_uart2(b"123456789", 0.1)
    assert not board.uart2_control
    board.receive_uart2(b"0", 0.2)
    assert board.uart2_control
    assert board.direction == 0, "the APP port's direction is dropped"
    board.receive(b"A", 0.3)
    assert board.direction == 0
    assert any("ignored: UART2 drives" in n.text and n.port == "uart3" for n in board.notes)
    assert any("takes over" in n.text and n.port == "uart2" for n in board.notes)


def test_s8_3_after_takeover_app_frames_still_work() -> None:
    board = Board()
    board.receive_uart2(control.STOP, 0.0)
    board.receive(b"{0:800}{Q:P}", 0.1)
    assert board.params[params.MAX_SPEED] == 800
    assert b"{C800:" in board.poll(0.3)


def test_s8_3_the_reference_firmware_takes_over_at_the_eleventh_byte() -> None:
    board = Board(profile=MINIBALANCE)
    board.receive_uart2(b"x" * 10, 1.1)
    assert not board.uart2_control
    board.receive_uart2(b"x", 1.2)
    assert board.uart2_control


def test_s8_2_garbage_and_unknown_modes_are_counted_and_the_board_keeps_serving() -> None:
    board = Board()
    board.receive_uart2(b"\x00" * 100 + bytes.fromhex("FF FE 07"), 0.0)
    board.receive_uart2(encode(control.velocity(DriveType.OMNI, y=300)), 0.1)
    assert board.uart2_errors == 3  # two runs of garbage (64 + 36 bytes) and the mode 07
    assert a_records(board, 1.5)[-1].y == 300


def test_s8_2_a_frame_split_at_every_byte_is_applied_once_whole() -> None:
    raw = encode(control.velocity(DriveType.OMNI, y=250))
    board = Board()
    for i, byte in enumerate(raw):
        board.receive_uart2(bytes([byte]), 0.001 * i)
        if i < len(raw) - 1:
            assert not any("velocity" in n.text for n in board.notes)
    assert a_records(board, 1.5)[-1].y == 250


def test_s9_1_velocity_omni_drives_the_a_record_clamped_to_max_speed() -> None:
    board = Board()
    board.receive_uart2(encode(control.velocity(DriveType.OMNI, -100, 9000, 50)), 0.0)
    last = a_records(board, 1.5)[-1]
    assert (last.x, last.y, last.z) == (-100, 500, 50)


def test_s9_1_diff_duty_is_a_fraction_of_max_speed() -> None:
    board = Board(drive=DriveType.DIFF)
    board.receive_uart2(encode(control.VelocityFrame(0, 500, -2000)), 0.0)  # over 1000
    last = a_records(board, 1.5)[-1]
    assert (last.x, last.y, last.z) == (0, 250, -500)


def test_s9_1_diff_gyro_left_and_right() -> None:
    board = Board(drive=DriveType.DIFF_GYRO)
    frame = control.velocity(DriveType.DIFF_GYRO, left=1000, right=200)
    board.receive_uart2(encode(frame), 0.0)
    last = a_records(board, 1.5)[-1]
    assert (last.y, last.z) == (300, 200)


def test_s9_1_angle_mode_accumulates_and_turns_the_angle_off() -> None:
    board = Board()
    ninety = encode(control.velocity(DriveType.OMNI, angle=900))
    board.receive_uart2(ninety, 0.0)
    board.receive_uart2(ninety, 0.0)
    assert board.pending_angle == 1800
    pending = read(board, "pending_angle", 0.5)
    assert 0 < pending < 1800
    board.advance(10.0)
    assert board.pending_angle == 0
    assert abs(board.vehicle.heading - 180) < 10


def test_s9_1_no_angle_mode_on_the_reference_firmware() -> None:
    board = Board(profile=MINIBALANCE)
    board.receive_uart2(b"\0" * 11, 1.0)
    board.receive_uart2(encode(control.velocity(DriveType.OMNI, angle=20)), 1.1)
    assert board.pending_angle == 0
    board.advance(2.0)
    assert board.vehicle.vz == 20  # the field is z


def test_s9_2_motor_speeds_move_the_body_as_the_kinematics_say() -> None:
    board = Board(drive=DriveType.MECANUM)
    board.receive_uart2(encode(MotorFrame((300, 300, 300, 300))), 0.0)
    assert a_records(board, 1.5)[-1].y == 300
    board.receive_uart2(encode(MotorFrame((100, -100, 100, -100))), 1.5)
    last = a_records(board, 3.0)[-1]
    assert (last.x, last.y) == (100, 0)
    assert read(board, "speed_a", 3.0) == 100 and read(board, "speed_b", 3.1) == -100


def test_s9_2_omni_three_motors_and_wheel_d_reads_zero() -> None:
    board = Board()
    board.receive_uart2(encode(MotorFrame((100, 100, 100))), 0.0)
    board.advance(1.5)
    assert round(board.vehicle.vz) == 100 and round(board.vehicle.vy) == 0
    assert read(board, "speed_c", 1.5) == 100
    assert read(board, "speed_d", 1.6) == 0


def test_s9_2_a_motor_frame_outlives_a_change_of_drive_type() -> None:
    """A 3-motor frame then a 4-wheel type: motor 4 runs at 0 (the board used to raise
    at its next tick); and back to an omni: motor 4 is ignored."""
    board = Board()
    board.receive_uart2(encode(MotorFrame((100, 100, 100))), 0.0)
    set_setting(board, "system_mode", 0x41, 0.5)  # mecanum, encoder report on
    reports = [
        e
        for e in control_decoders.ReplyDecoder(4).feed(board.poll_uart2(3.0))
        if isinstance(e, control.EncoderReport)
    ]
    assert reports and reports[-1].targets == (100, 100, 100, 0)
    assert round(board.vehicle.vy) == 75  # the mecanum body of (100, 100, 100, 0)
    board.receive_uart2(encode(MotorFrame((300, 300, 300, 300))), 3.0)
    set_setting(board, "system_mode", 0x40, 3.5)  # omni
    board.advance(6.0)
    assert round(board.vehicle.vz) == 300 and round(board.vehicle.vy) == 0


def test_s9_3_position_mode_moves_by_the_clamped_displacement_and_holds() -> None:
    board = Board()
    set_setting(board, "max_position", 400, 0.0)
    board.receive_uart2(encode(PositionFrame(0, 1000, 0)), 0.01)
    board.advance(10.0)
    assert abs(board.vehicle.travel_y - 400) < 2
    assert abs(board.vehicle.vy) < 1
    assert abs(read(board, "position_a", 10.0) - 400 * 0.866) < 3


def test_s9_3_no_position_mode_on_a_differential_drive() -> None:
    board = Board(drive=DriveType.DIFF)
    board.receive_uart2(encode(PositionFrame(0, 100, 0)), 0.0)
    assert board.uart2_errors == 1
    assert any("no position mode" in n.text for n in board.notes)


def test_s10_settings_are_the_app_parameters_both_ways() -> None:
    board = Board()
    set_setting(board, "max_speed", 800, 0.0)
    board.receive(b"{1:1234}", 0.0)
    assert board.params[params.MAX_SPEED] == 800
    assert read(board, "max_position", 0.1) == 1234


def test_s10_every_setting_set_and_read_back() -> None:
    board = Board()
    for i, setting in enumerate(settings.SETTINGS):
        value = 1 if setting.name == "system_mode" else 4321
        set_setting(board, setting.name, value, i * 0.1)
        assert read(board, setting.name, i * 0.1 + 0.02) == value


def test_s10_out_of_range_changes_nothing_and_is_counted() -> None:
    board = Board()
    board.receive_uart2(bytes.fromhex("FF FE 80 80 01 00 01 00 00 00"), 0.0)
    board.receive_uart2(bytes.fromhex("FF FE 80 80 09 00 00 00 05 00"), 0.0)
    assert board.uart2_errors == 2
    assert board.params[params.MAX_SPEED] == 500
    assert board.params[params.SYSTEM_MODE] == 0


def test_s10_load_save_defaults_across_a_restart() -> None:
    store = MemoryStore()
    board = Board(store)
    set_setting(board, "max_speed", 900, 0.0)
    set_setting(board, "gyro_calibration", 0xFFFF, 0.0)
    board.receive_uart2(encode(control.store("save")), 0.0)
    set_setting(board, "max_speed", 100, 0.1)
    board.receive_uart2(encode(control.store("load")), 0.2)
    assert board.params[params.MAX_SPEED] == 900
    board.receive_uart2(encode(control.store("defaults")), 0.3)
    assert board.params[params.MAX_SPEED] == 500 and board.gyro_calibration == 0
    again = Board(store)
    assert again.params[params.MAX_SPEED] == 900 and again.gyro_calibration == 0xFFFF


def test_s10_a_save_from_the_app_port_saves_gyro_calibration_too() -> None:
    store = MemoryStore()
    board = Board(store)
    set_setting(board, "gyro_calibration", 7, 0.0)
    board.receive(b"{Q:W}", 0.1)
    assert Board(store).gyro_calibration == 7


def test_s11_reply_goes_out_in_the_next_tick() -> None:
    board = Board()
    board.receive_uart2(bytes.fromhex("FF FE 80 80 11 00 00 00 00 00"), 0.012)
    assert board.poll_uart2(0.0199) == b""
    assert board.poll_uart2(0.020) == bytes.fromhex("23 01 00 00 01 F4")
    assert board.next_slot() == 0.05


def test_s11_unknown_read_is_ignored_and_counted() -> None:
    board = Board()
    board.receive_uart2(bytes.fromhex("FF FE 80 80 30 00 00 00 00 00"), 0.0)
    assert board.poll_uart2(0.1) == b"" and board.uart2_errors == 1


def test_s12_encoder_report_every_50_ms_while_bit_6_is_set() -> None:
    board = Board(drive=DriveType.MECANUM)
    board.receive_uart2(encode(control.velocity(DriveType.MECANUM, y=200)), 0.0)
    set_setting(board, "system_mode", 1 | params.MODE_BIT["encoder_report"], 0.0)
    events = control_decoders.ReplyDecoder(4).feed(board.poll_uart2(2.0))
    reports = [e for e in events if isinstance(e, control.EncoderReport)]
    assert len(reports) == 40
    assert reports[-1].targets == (200, 200, 200, 200) == reports[-1].actuals
    board.receive(b"{8:1}", 2.0)  # off again from the APP port
    assert board.poll_uart2(3.0) == b""


def test_s12_each_report_shows_the_wheels_as_they_are_then() -> None:
    """A car driving steadily reports the same wheels; what changes them (the velocity,
    encoder_reverse, the drive type, a motor frame) is in the next report."""
    board = Board(drive=DriveType.MECANUM)
    report = params.MODE_BIT["encoder_report"]

    def last(now: float, wheels: int = 4) -> control.EncoderReport:
        events = control_decoders.ReplyDecoder(wheels).feed(board.poll_uart2(now))
        return [e for e in events if isinstance(e, control.EncoderReport)][-1]

    set_setting(board, "system_mode", DriveType.MECANUM | report, 0.0)
    board.receive_uart2(encode(control.velocity(DriveType.MECANUM, y=200)), 0.0)
    assert last(2.0).actuals == (200, 200, 200, 200)
    assert last(2.5).actuals == (200, 200, 200, 200), "steady: the same report"
    reverse = params.MODE_BIT["encoder_reverse"]
    set_setting(board, "system_mode", DriveType.MECANUM | report | reverse, 2.5)
    assert last(2.56).actuals == (-200, -200, -200, -200) == last(2.56 + 0.05).targets
    board.receive_uart2(encode(control.velocity(DriveType.MECANUM, x=100, y=200)), 2.61)
    assert last(2.66).targets == (-300, -100, -300, -100)
    assert last(4.0).actuals == (-300, -100, -300, -100)
    board.receive_uart2(encode(control.MotorFrame((10, 20, 30, 40))), 4.0)
    assert last(6.0).targets == (-10, -20, -30, -40)
    board.receive_uart2(encode(control.MotorFrame((11, 21, 29, 39))), 6.0)  # the same body
    assert last(6.06).targets == (-11, -21, -29, -39)
    set_setting(board, "system_mode", DriveType.OMNI | report, 6.06)
    assert last(6.11, wheels=3).targets == (11, 21, 29)


def test_s12_app_mode_moves_the_app_protocol_to_uart2() -> None:
    board = Board()
    set_setting(board, "system_mode", params.MODE_BIT["app_mode"], 0.01)
    board.poll(0.01)
    assert board.poll(1.0) == b"", "UART3's transmitter is idle"
    assert b"{A0:0:0:0}$" in board.poll_uart2(1.0)
    board.receive_uart2(b"A", 1.0)
    assert board.uart2_control and board.direction == 1, "letters on UART2 drive"
    board.receive(b"{8:0}", 1.5)  # UART3 still receives and obeys
    board.poll_uart2(1.5)
    assert board.poll(2.0) != b"" and board.poll_uart2(2.0) == b""


def test_s8_3_the_stop_frame_also_drops_a_pending_rotation() -> None:
    board = Board()
    board.receive_uart2(encode(control.velocity(DriveType.OMNI, angle=900)), 0.0)
    board.advance(0.5)
    assert board.pending_angle > 0
    board.receive_uart2(control.STOP, 0.5)
    board.advance(1.5)
    assert board.pending_angle == 0 and abs(board.vehicle.vz) < 1


def test_each_port_plans_only_what_it_sends() -> None:
    """A served port wakes for its own output: UART3 for records, UART2 for replies and
    reports (and records in APP mode)."""
    board = Board(drive=DriveType.MECANUM)
    board.poll(0.0)
    uart3, uart2, _ = board.next_sends()
    assert uart3 > 0 and uart2 == float("inf"), "no report, no read: UART2 plans nothing"
    board.receive_uart2(encode(control.read("max_speed")), 0.001)
    assert board.next_sends()[1] == 0.01, "a read: its reply in the next tick"
    board.poll_uart2(0.011)
    set_setting(board, "system_mode", 1 | params.MODE_BIT["encoder_report"], 0.012)
    assert board.next_sends()[1] == 0.05, "the next report, on the 50 ms grid"
    set_setting(board, "system_mode", 1 | params.MODE_BIT["app_mode"], 0.02)
    board.poll(0.03)
    uart3, uart2, _ = board.next_sends()
    assert uart3 == float("inf") and uart2 < 0.2, "APP mode: records on UART2, UART3 idle"
    assert board.next_slot() == uart2


speed = st.integers(-1000, 1000)
frame = st.one_of(
    st.builds(
        lambda a, b, c, angle: control.VelocityFrame(a, b, c, angle),
        speed,
        speed,
        speed,
        st.booleans(),
    ),
    st.builds(lambda v: MotorFrame(tuple(v)), st.lists(speed, min_size=3, max_size=4)),
    st.builds(PositionFrame, speed, speed, speed),
    st.builds(  # any drive type, encoder report and APP mode on or off
        lambda mode: SetSetting(settings.BY_NAME["system_mode"], mode),
        st.sampled_from([0, 1, 2, 3]).flatmap(
            lambda drive: st.sampled_from([drive, drive | 0x40, drive | 0x80, drive | 0xC0])
        ),
    ),
    st.sampled_from(settings.READS).map(control.ReadFrame),
).map(encode) | st.sampled_from([b"A", b"Z", b"{Q:P}", b"{8:1}", b"{8:64}"]).map(
    lambda b: b"app" + b
)


@hypothesis_settings(max_examples=150, deadline=None)
@given(
    st.sampled_from([SHEET, MINIBALANCE]),
    st.lists(st.tuples(st.floats(0, 0.5), frame), max_size=20),
)
def test_property_no_sequence_of_valid_frames_stops_the_board(
    profile: Profile, steps: list[tuple[float, bytes]]
) -> None:
    """Whatever valid frames come on either port, in any order (a drive type changed
    under a motor frame, APP mode on and off, reads), the board keeps running: its
    records go on, on one port or the other."""
    board = Board(profile=profile, drive=DriveType.OMNI if profile.drive_types else None)
    now = 0.0
    for gap, data in steps:
        now += gap
        if data.startswith(b"app"):
            board.receive(data[3:], now)
        else:
            board.receive_uart2(data, now)
        board.poll(now)
        board.poll_uart2(now)
    assert board.poll(now + 2.0) + board.poll_uart2(now + 2.0)
