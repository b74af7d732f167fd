"""docs/protocol.md §2–§6 as the board model behaves: directions, pages, timing, parameters."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from appmode.board.firmware import SLOT, Board
from appmode.board.profiles import MINIBALANCE, SHEET, Profile
from appmode.board.store import JsonFileStore, MemoryStore
from appmode.board.vehicle import battery_percent, wrap_degrees
from appmode.protocol import control, params
from appmode.protocol import settings as board_settings
from appmode.protocol.app import Attitude, ParamsRecord, Velocity
from appmode.protocol.app_decoders import BoardDecoder
from appmode.protocol.params import DriveType

S = 500
# §4, direction page, copied from docs/protocol.md: letter -> (omni/mecanum x,y,z), (diff y,z)
DIRECTION_PAGE = {
    "A": ((0, S, 0), (S, 0)),
    "B": ((S, S, 0), (S, S // 2)),
    "C": ((S, 0, 0), (0, S)),
    "D": ((S, -S, 0), (-S, -S // 2)),
    "E": ((0, -S, 0), (-S, 0)),
    "F": ((-S, -S, 0), (-S, S // 2)),
    "G": ((-S, 0, 0), (0, -S)),
    "H": ((-S, S, 0), (S, -S // 2)),
}
# §4, button page: A fwd, E back, C cw, G ccw, B front-left, H front-right, F rl, D rr
BUTTON_PAGE = {
    "A": ((0, S, 0), (S, 0)),
    "B": ((-S, S, 0), (S, -S // 2)),
    "C": ((0, 0, S), (0, S)),
    "D": ((S, -S, 0), (-S, -S // 2)),
    "E": ((0, -S, 0), (-S, 0)),
    "F": ((-S, -S, 0), (-S, S // 2)),
    "G": ((0, 0, -S), (0, -S)),
    "H": ((S, S, 0), (S, S // 2)),
}


def records(board: Board, until: float) -> list[object]:
    decoder = BoardDecoder()
    return decoder.feed(board.poll(until)) + decoder.flush()


def settled_velocity(drive: DriveType, page_letter: bytes, letter: bytes) -> Velocity:
    board = Board(drive=drive)
    board.receive(page_letter + letter, 0.0)
    got = [r for r in records(board, 2.0) if isinstance(r, Velocity)]
    return got[-1]


@pytest.mark.parametrize("drive", [DriveType.OMNI, DriveType.MECANUM])
@pytest.mark.parametrize(("page", "table"), [(b"J", DIRECTION_PAGE), (b"K", BUTTON_PAGE)])
def test_s4_every_letter_holonomic(
    drive: DriveType, page: bytes, table: dict[str, tuple[tuple[int, ...], ...]]
) -> None:
    for letter, (xyz, _) in table.items():
        assert settled_velocity(drive, page, letter.encode()) == Velocity(*xyz, 0), letter


@pytest.mark.parametrize("drive", [DriveType.DIFF, DriveType.DIFF_GYRO])
@pytest.mark.parametrize(("page", "table"), [(b"I", DIRECTION_PAGE), (b"K", BUTTON_PAGE)])
def test_s4_every_letter_differential(
    drive: DriveType, page: bytes, table: dict[str, tuple[tuple[int, ...], ...]]
) -> None:
    for letter, (_, yz) in table.items():
        assert settled_velocity(drive, page, letter.encode()) == Velocity(0, *yz, 0), letter


def test_s2_1_raw_direction_bytes_drive_like_letters() -> None:
    for n, letter in enumerate("ABCDEFGH", start=1):
        assert settled_velocity(DriveType.MECANUM, b"J", bytes([n])) == settled_velocity(
            DriveType.MECANUM, b"J", letter.encode()
        )


def test_s2_1_i_and_j_are_the_same_page() -> None:
    for letter in "ABCDEFGH":
        assert settled_velocity(DriveType.OMNI, b"I", letter.encode()) == settled_velocity(
            DriveType.OMNI, b"J", letter.encode()
        )


def test_s2_1_board_keeps_last_direction_until_next_byte() -> None:
    board = Board(drive=DriveType.MECANUM)
    board.receive(b"A", 0.0)
    assert [r for r in records(board, 10.0) if isinstance(r, Velocity)][-1].y == S


@pytest.mark.parametrize("byte", [b"Z", b"x", b"\x00", b"\r", b"\xff", b"+", b"I", b"K"])
def test_s2_1_stop_and_any_unrecognised_byte_stops(byte: bytes) -> None:
    board = Board(drive=DriveType.MECANUM)
    board.receive(b"A", 0.0)
    board.receive(byte, 1.0)
    last = [r for r in records(board, 3.0) if isinstance(r, Velocity)][-1]
    assert last == Velocity(0, 0, 0, 0)


def test_s2_1_unrecognised_byte_is_counted_as_an_error() -> None:
    board = Board()
    board.receive(b"x", 0.0)
    assert board.errors == 1
    assert any("unrecognised" in n.text for n in board.take_notes())


def test_s2_2_frames_do_not_change_the_direction() -> None:
    board = Board(drive=DriveType.MECANUM)
    board.receive(b"A{Q:P}{5:11}{Q:W}{bad}", 0.0)
    assert [r for r in records(board, 2.0) if isinstance(r, Velocity)][-1].y == S


def test_s3_4_a_and_b_alternate_every_50_ms() -> None:
    board = Board()
    decoder = BoardDecoder()
    kinds = []
    for k in range(20):
        now = k * SLOT
        events = decoder.feed(board.poll(now))
        assert len(events) == 1, f"one record per slot at {now}"
        kinds.append(type(events[0]))
    assert kinds == [Velocity, Attitude] * 10


def test_s3_4_nothing_between_slots() -> None:
    board = Board()
    assert board.poll(0.0) != b""
    assert board.poll(0.049) == b""
    assert board.poll(0.050) != b""
    assert board.next_slot() == pytest.approx(0.1)


def test_s3_3_c_record_takes_the_next_slot_once() -> None:
    board = Board()
    board.poll(0.0)
    board.receive(b"{Q:P}", 0.01)
    slots = [BoardDecoder().feed(board.poll(k * SLOT)) for k in range(1, 5)]
    assert slots[0] == [ParamsRecord(params.DEFAULTS)]
    assert [type(s[0]) for s in slots[1:]] == [Velocity, Attitude, Velocity]


def test_s3_4_c_record_keeps_alternation_phase() -> None:
    """The A/B flag flips on a C slot too (ref firmware), so C replaces one of them."""
    board = Board()
    board.receive(b"{Q:P}", 0.0)  # slot 0 already sent A
    assert isinstance(BoardDecoder().feed(board.poll(0.0))[0], Velocity)
    kinds = [type(BoardDecoder().feed(board.poll(k * SLOT))[0]) for k in range(1, 4)]
    assert kinds == [ParamsRecord, Velocity, Attitude]


def test_s3_1_fourth_field_of_a_is_zero_and_sign_conventions() -> None:
    board = Board(drive=DriveType.OMNI)
    board.receive(b"JF", 0.0)
    last = [r for r in records(board, 2.0) if isinstance(r, Velocity)][-1]
    assert (last.x, last.y, last.extra) == (-S, -S, 0)


def test_s3_2_yaw_turns_clockwise_positive_and_wraps() -> None:
    board = Board(drive=DriveType.MECANUM)
    board.receive(b"KC", 0.0)
    yaws = [r.yaw for r in records(board, 1.5) if isinstance(r, Attitude)]
    assert yaws[-1] > 45 and yaws == sorted(yaws)
    board.receive(b"Z", 1.5)
    board.receive(b"G", 2.0)
    yaws = [r.yaw for r in records(board, 3.0) if isinstance(r, Attitude)]
    assert yaws[-1] < yaws[0] - 45, "counter-clockwise turns yaw down"
    yaws = [
        r.yaw for k in range(31) for r in records(board, 3.0 + k * 0.5) if isinstance(r, Attitude)
    ]
    assert min(yaws) < -170 and max(yaws) > 170, "a full turn passes the wrap point"
    assert all(-179 <= y <= 180 for y in yaws)


def test_s3_2_battery_percent_formula() -> None:
    assert battery_percent(1260) == 100
    assert battery_percent(1300) == 100
    assert battery_percent(1185) == 50
    assert battery_percent(1110) == 0
    assert battery_percent(1000) == 0
    assert wrap_degrees(180) == 180 and wrap_degrees(181) == -179 and wrap_degrees(-180) == 180


def test_s3_2_battery_drains_faster_when_moving() -> None:
    idle, moving = Board(), Board()
    moving.receive(b"A", 0.0)
    idle.poll(600.0)
    moving.poll(600.0)
    assert moving.vehicle.centivolts < idle.vehicle.centivolts < 1260


def test_s5_set_changes_running_copy_and_c_record_shows_it() -> None:
    board = Board()
    board.receive(b"{0:800}{7:12345}{Q:P}", 0.0)
    [c] = [r for r in records(board, 0.1) if isinstance(r, ParamsRecord)]
    assert c.values[0] == 800 and c.values[7] == 12345


def test_s5_max_speed_scales_the_motion() -> None:
    board = Board(drive=DriveType.MECANUM)
    board.receive(b"{0:800}JA", 0.0)
    assert [r for r in records(board, 2.0) if isinstance(r, Velocity)][-1].y == 800


def test_s2_2_rejected_set_changes_nothing_and_counts_an_error() -> None:
    board = Board()
    board.receive(b"{0:70000}{8:5}{0:}{0:1x}", 0.0)
    assert board.params == list(params.DEFAULTS)
    assert board.errors == 4


def test_s2_2_wrong_separator_q_frame_is_answered_and_warned() -> None:
    board = Board()
    board.receive(bytes.fromhex("7B 51 03 50 7D"), 0.0)
    assert any(isinstance(r, ParamsRecord) for r in records(board, 0.1))
    assert board.warnings == 1


def test_s5_boot_from_saved_or_factory_defaults(tmp_path: Path) -> None:
    path = tmp_path / "flash.json"
    board = Board(JsonFileStore(path))
    assert board.params == list(params.DEFAULTS)
    assert "no saved parameters" in board.take_notes()[0].text
    board.receive(b"{0:800}{8:%d}{Q:W}{1:5}" % (0xC3,), 0.0)
    again = Board(JsonFileStore(path))
    assert again.params[0] == 800
    assert again.params[1] == 10000, "only {Q:W} saves"
    assert again.params[8] == 0x03, "bits 6 and 7 are never saved"
    saved = json.loads(path.read_text())
    assert saved["params"]["max_speed"] == 800


def test_s5_set_without_save_is_lost_on_reboot() -> None:
    store = MemoryStore()
    Board(store).receive(b"{0:900}", 0.0)
    assert Board(store).params[0] == 500


@pytest.mark.parametrize(
    "content",
    [
        "",
        "{",
        "[]",
        '{"format": "other"}',
        '{"format": "appmode-flash", "version": 1}',
        '{"format": "appmode-flash", "version": 1, "params": {"max_speed": 1}}',
        json.dumps(
            {
                "format": "appmode-flash",
                "version": 1,
                "params": {p.name: 99999999999 for p in params.PARAMS},
            }
        ),
    ],
)
def test_s5_corrupt_flash_means_defaults_and_a_warning(tmp_path: Path, content: str) -> None:
    path = tmp_path / "flash.json"
    path.write_text(content)
    board = Board(JsonFileStore(path))
    assert board.params == list(params.DEFAULTS)
    [note] = board.take_notes()
    assert note.level == "warning" and str(path) in note.text


def test_s5_save_is_atomic_and_leaves_no_temporary_files(tmp_path: Path) -> None:
    path = tmp_path / "flash.json"
    store = JsonFileStore(path)
    for value in range(5):
        store.save([value, *params.DEFAULTS[1:]])
    assert [p.name for p in tmp_path.iterdir()] == ["flash.json"]
    assert store.load() == ((4, *params.DEFAULTS[1:]), None)


def test_s5_failed_save_is_reported_not_raised(tmp_path: Path) -> None:
    board = Board(JsonFileStore(tmp_path / "missing-dir" / "flash.json"))
    board.receive(b"{Q:W}", 0.0)
    assert board.errors == 1
    assert any("save failed" in n.text for n in board.take_notes())


def test_s6_drive_option_sets_bits_0_to_2_of_running_copy() -> None:
    store = MemoryStore((*params.DEFAULTS[:8], 0x100))
    board = Board(store, drive=DriveType.DIFF_GYRO)
    assert board.params[8] == 0x103


def test_s6_motor_and_encoder_reverse() -> None:
    for mode, sign in ((0x100, -1), (0x200, -1), (0x300, 1)):
        board = Board(MemoryStore((*params.DEFAULTS[:8], 1 | mode)))
        board.receive(b"JA", 0.0)
        assert [r for r in records(board, 2.0) if isinstance(r, Velocity)][-1].y == sign * S


def test_time_never_goes_backwards() -> None:
    board = Board()
    board.poll(1.0)
    assert board.poll(0.5) == b""
    board.receive(b"A", 0.2)  # applied at the board's own time
    assert board.direction == 1


def test_a_long_stall_skips_ahead_instead_of_flooding() -> None:
    board = Board()
    data = board.poll(3600.0)
    assert len(BoardDecoder().feed(data)) <= 50


script = st.lists(
    st.tuples(
        st.floats(0, 0.3),
        st.binary(max_size=6)
        | st.sampled_from([b"A", b"C", b"Z", b"K", b"{Q:P}", b"{0:900}", b"{Q:W}"]),
    ),
    max_size=25,
)


@settings(max_examples=50)
@given(script, st.lists(st.floats(0.001, 0.2), min_size=1, max_size=30))
def test_property_board_is_deterministic(
    steps: list[tuple[float, bytes]], polls: list[float]
) -> None:
    """Same inputs at the same times give the same bytes, however often poll is called."""

    def run(poll_gaps: list[float]) -> bytes:
        board = Board(drive=DriveType.MECANUM)
        out = bytearray()
        now = 0.0
        gaps = iter(poll_gaps)
        for gap, data in steps:
            target = now + gap
            while (g := next(gaps, None)) is not None and now + g < target:
                now += g
                out += board.poll(now)
            now = target
            board.receive(data, now)
        out += board.poll(now + 1.0)
        return bytes(out)

    assert run(polls) == run(polls) == run([])


@pytest.mark.parametrize("profile", [SHEET, MINIBALANCE], ids=["sheet", "minibalance"])
def test_an_idle_car_run_in_one_go_is_the_car_run_tick_by_tick(profile: Profile) -> None:
    """Issue 28.5: the ticks of a resting car are run at once (its battery drains, nothing
    else happens); what it sends and its battery are exactly those of a car run in steps
    shorter than a tick, also when it drives between rests."""
    script = [(5.0, b"A"), (6.0, b"Z"), (20.0, b"C"), (21.0, b"Z")]

    def run(step: float) -> tuple[bytes, float]:
        board, out, t, pending = Board(profile=profile), bytearray(), 0.0, list(script)
        while t < 40.0:
            t = min(t + step, 40.0)
            while pending and pending[0][0] <= t:
                when, data = pending.pop(0)
                board.receive(data, when)
            out += board.poll(t)
        return bytes(out), board.vehicle.centivolts

    fine = run(0.003)
    assert run(0.5) == fine
    assert run(0.047) == fine
    assert fine[1] < Board(profile=profile).vehicle.centivolts  # the battery did drain


@pytest.mark.parametrize(
    "profile",
    [SHEET, dataclasses.replace(SHEET, period_ms=70), MINIBALANCE],
    ids=["sheet", "records-every-70-ms", "minibalance"],
)
def test_a_driving_car_run_in_one_go_is_the_car_run_tick_by_tick(profile: Profile) -> None:
    """Issue 28.4: the ticks of a driving car between two records are run at once; what
    both ports send, and where the car ends, are exactly those of a car run in steps
    shorter than a tick: driven from either port, with the encoder report (also when it
    does not fall with a record), reads (answered in the tick after them, also while the
    car speeds up), an angle to turn and a position to reach."""
    mecanum = control.SetSetting(board_settings.BY_NAME["system_mode"], 0x41)
    frames = [
        (1.0, "app", b"A"),
        (2.5, "app", b"G"),
        (3.0, "uart2", control.encode(mecanum)),
        (3.2, "uart2", control.encode(control.velocity(DriveType.MECANUM, 100, 300, 20))),
        (3.204, "uart2", control.encode(control.read("speed_b"))),  # while it speeds up
        (4.013, "uart2", control.encode(control.read("speed_b"))),
        (5.0, "uart2", control.encode(control.velocity(DriveType.MECANUM, y=200, angle=900))),
        (7.0, "uart2", control.encode(control.PositionFrame(300, -200, 0))),
        (9.0, "uart2", control.encode(control.MotorFrame((100, 200, 300, 400)))),
        (11.0, "uart2", control.STOP),
    ]

    def run(step: float) -> tuple[bytes, bytes, tuple[float, ...]]:
        board, t, pending = Board(profile=profile), 0.0, list(frames)
        out, out2 = bytearray(), bytearray()
        while t < 13.0:
            t = min(t + step, 13.0)
            while pending and pending[0][0] <= t:
                when, port, data = pending.pop(0)
                (board.receive if port == "app" else board.receive_uart2)(data, when)
            out += board.poll(t)
            out2 += board.poll_uart2(t)
        v = board.vehicle
        return bytes(out), bytes(out2), (v.east, v.north, v.heading, v.centivolts)

    fine = run(0.003)
    assert len(fine[1]) > 500  # encoder reports (status bursts on the reference firmware)
    assert run(0.5) == fine
    assert run(0.047) == fine


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(0.001, 0.2), st.sampled_from([b"A", b"C", b"Z", b"{Q:P}"]))))
def test_poll_ports_is_poll_then_poll_uart2(inputs: list[tuple[float, bytes]]) -> None:
    """One run of the board for both ports gives what polling each port gives."""
    one, twin = Board(drive=DriveType.MECANUM), Board(drive=DriveType.MECANUM)
    for board in (one, twin):
        board.receive_uart2(
            control.encode(control.SetSetting(board_settings.BY_NAME["system_mode"], 0x41)), 0.0
        )
    now = 0.0
    for gap, data in inputs:
        now += gap
        one.receive(data, now)
        twin.receive(data, now)
        assert one.poll_ports(now) == (twin.poll(now), twin.poll_uart2(now), b"")


@pytest.mark.parametrize("target", [(0.0, 300.0, 0.0), (-0.0, -120.5, 40.0), (250.0, 0.0, -0.0)])
def test_a_car_at_its_target_stays_there_and_moves_at_it(
    target: tuple[float, float, float],
) -> None:
    car = Board().vehicle
    car.vx, car.vy, car.vz = target
    before = dataclasses.replace(car)
    car.step(target, 0.01)
    assert (car.vx, car.vy, car.vz) == target
    assert (car.pitch, car.roll) == (0.0, 0.0)
    assert car.travel_y - before.travel_y == target[1] * 0.01
    assert car.centivolts < before.centivolts


velocities = st.tuples(*[st.sampled_from([0.0, -0.0, 0.3, 250.0, -120.5])] * 3)


@settings(max_examples=200, deadline=None)
@given(velocities, velocities, st.integers(1, 12), st.floats(0, 359))
def test_steps_in_one_go_are_the_steps_one_by_one(
    start: tuple[float, float, float],
    target: tuple[float, float, float],
    ticks: int,
    heading: float,
) -> None:
    """`step(target, dt, ticks)` leaves the car exactly where `ticks` steps leave it:
    at rest, reaching its target on the way, at its target, turning."""
    one = Board().vehicle
    one.vx, one.vy, one.vz = start
    one.heading = heading
    twin = dataclasses.replace(one)
    one.step(target, 0.01, ticks)
    for _ in range(ticks):
        twin.step(target, 0.01)
    assert one == twin
