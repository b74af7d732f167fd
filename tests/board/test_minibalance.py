"""The minibalance profile: every row of docs/protocol.md §13, at the firmware's edges."""

from __future__ import annotations

import dataclasses
import itertools

import pytest

from appmode.board.firmware import Board
from appmode.board.profiles import MINIBALANCE, PROFILES, SHEET
from appmode.board.store import MemoryStore
from appmode.board.vehicle import battery_percent
from appmode.errors import AppmodeError
from appmode.protocol import app, app_decoders
from appmode.protocol.params import DriveType

ON = 2.0
"""After the dead time, when the motors are on (§13.1: the battery is valid 1.9 s after
power-up)."""


def board(**kwargs: object) -> Board:
    return Board(profile=MINIBALANCE, **kwargs)  # type: ignore[arg-type]


def records(
    b: Board, start: float, end: float, step: float = 0.001
) -> list[tuple[float, app.Record]]:
    """Each record with the time the board sent it (to the ms)."""
    out = []
    decoder = app_decoders.BoardDecoder()
    t = start
    while t <= end + 1e-9:
        for event in decoder.feed(b.poll(t)):
            if isinstance(event, app.RECORDS):
                out.append((round(t, 3), event))
        t = round(t + step, 3)
    return out


def params_after(b: Board, data: bytes, at: float = ON) -> tuple[int, ...]:
    b.receive(data + b"{Q:P}", at)
    for _, record in records(b, at, at + 0.2):
        if isinstance(record, app.ParamsRecord):
            return record.values
    raise AssertionError("no C record")


def test_s13_every_profile_is_one_row_of_the_same_switches() -> None:
    fields = {f.name for f in dataclasses.fields(SHEET)}
    assert set(PROFILES) == {"sheet", "minibalance"}
    differ = {f for f in fields if getattr(SHEET, f) != getattr(MINIBALANCE, f)}
    assert {"firmware_frames", "saves", "ramp", "a_layout", "period_ms"} <= differ
    third = dataclasses.replace(MINIBALANCE, name="third", first_record="A", dead_time=0.0)
    first = records(Board(profile=third), 1.3, 1.5)[0][1]
    assert isinstance(first, app.Velocity), "a third board is a row of values"


def test_s13_frame_bytes_steer_a_frame_stops_the_car() -> None:
    b = board()
    b.receive(b"JA", ON)
    assert b.direction == 1
    b.receive(b"{", ON + 0.1)
    assert b.direction == 0, "{ is an unknown byte: stop"
    b.receive(b"\x03Q:P}", ON + 0.2)
    assert b.direction == 0, "} stops too"
    b.receive(b"{\x03", ON + 0.3)
    assert b.direction == 3, "a byte 0x01-0x08 inside a frame sets that direction"


def test_s13_a_brace_inside_a_frame_is_kept() -> None:
    assert params_after(board(), b"{0:{1:7}")[:2] == (75207, 3000)


def test_s13_q_frames_by_position_3_only() -> None:
    b = board()
    b.receive(b"{5:P}", ON)
    assert any(isinstance(r, app.ParamsRecord) for _, r in records(b, ON, ON + 0.2))
    b.receive(b"{Q:X}{QQ}", ON + 0.3)
    assert not any(isinstance(r, app.ParamsRecord) for _, r in records(b, ON + 0.3, ON + 0.6))


@pytest.mark.parametrize(
    ("frame", "index", "shown"),
    [
        (b"{0:}", 0, 0),
        (b"{0:1x}", 0, 82),
        (b"{1:-5}", 1, -25),
        (b"{1:{Q:P}", 1, 78432),
        (b"{2:16777217}", 2, 16777216),
        (b"{3:4000000000}", 3, 2147483647),
        (b"{4:-3000000000}", 4, -2147483648),
        (b"{5:000000000000000000000000000007}", 5, 7),
        (b"{1;9}", 1, 9),
    ],
)
def test_s13_set_value_arithmetic(frame: bytes, index: int, shown: int) -> None:
    assert params_after(board(), frame)[index] == shown


def test_s13_parameters_2_to_6_are_float32() -> None:
    b = board()
    b.receive(b"{2:16777217}{6:33554435}", ON)
    assert b.params[2] == 16777216.0 and isinstance(b.params[2], float)
    assert b.params[6] == 33554436.0


def test_s13_params_7_8_and_hash_frames_are_ignored() -> None:
    values = params_after(board(), b"{7:5}{8:2}{#:5}{9:1}")
    assert values == MINIBALANCE.defaults


def test_s13_max_speed_1_to_14_becomes_15_at_the_next_tick() -> None:
    b = board()
    b.receive(b"{0:5}", ON)
    assert b.params[0] == 5
    b.poll(ON + 0.011)
    assert b.params[0] == 15
    assert params_after(b, b"{0:0}", ON + 0.1)[0] == 0


def test_s13_saves_nothing_and_boots_from_factory_defaults() -> None:
    store = MemoryStore()
    b = Board(store, profile=MINIBALANCE)
    b.receive(b"{0:100}{Q:W}", ON)
    assert store.load() == (None, None)
    again = Board(store, profile=MINIBALANCE)
    assert again.params == list(MINIBALANCE.defaults) == [30, 3000, 40, 0, 40, 10, 10, 0, 0]


def test_s13_no_drive_types() -> None:
    with pytest.raises(AppmodeError, match="no drive types"):
        Board(profile=MINIBALANCE, drive=DriveType.DIFF)
    b = board()
    b.receive(b"{8:2}JC", ON)
    b.poll(ON + 1.0)
    assert b.vehicle.vx == 30 and b.vehicle.vy == 0, "C still moves sideways"


def test_s13_a_held_direction_ramps_and_coasts() -> None:
    b = board()
    b.receive(b"{0:30}JA", 2.0)
    b.poll(2.1)  # ticks at 2.01 … 2.10: ten of them
    assert b.vehicle.vy == pytest.approx(5.0)
    b.poll(3.0)
    assert b.vehicle.vy == 30.0, "capped at max_speed"
    b.receive(b"Z", 3.0)
    b.poll(3.01)
    assert b.vehicle.vy == pytest.approx(30 / 1.05)
    b.poll(3.1)
    assert b.vehicle.vy == pytest.approx(30 / 1.05**10)


def test_s13_button_page_letters_and_the_sticky_rotation() -> None:
    b = board()
    for letter in (b"B", b"D", b"F", b"H", b"\x01"):
        b.receive(b"KA" + letter, ON)
        assert b.direction == 0 and b.turn == 0, f"{letter!r} stops on the button page"
    b.receive(b"KC", ON)
    assert b.turn == 1
    b.receive(b"JZ", ON + 0.1)
    assert b.turn == 1, "after J, Z does not end the rotation"
    b.poll(ON + 1.0)
    assert b.vehicle.vz == 30
    b.receive(b"A", ON + 1.0)
    assert b.turn == 0, "a direction letter ends it"
    b.receive(b"KGE", ON + 1.1)
    assert (b.turn, b.direction) == (0, 5), "another button ends it"


def test_s13_a_record_layout_wraps() -> None:
    b = board()
    b.receive(b"{0:370}JB", ON)
    b.poll(ON + 8.0)
    assert b.vehicle.vx == b.vehicle.vy == 370
    a = next(r for _, r in records(b, ON + 8.0, ON + 8.2) if isinstance(r, app.Velocity))
    assert (a.x, a.y, a.extra) == (3, 3, 0), "|0.7·370| = 259 → 3"
    assert a.z == battery_percent(b.vehicle.centivolts, floor=False) >= 95


@pytest.mark.parametrize(("heading", "yaw"), [(10.9, 10), (180.0, -180), (359.5, 0), (190.5, -169)])
def test_s13_b_record_truncates_and_yaw_runs_to_minus_180(heading: float, yaw: int) -> None:
    b = board()
    b.poll(ON)
    b.vehicle.heading = heading
    attitude = next(r for _, r in records(b, ON, ON + 0.2) if isinstance(r, app.Attitude))
    assert attitude.yaw == yaw


def test_s13_telemetry_periods_and_b_first() -> None:
    b = board()
    timeline = records(b, 0, 2.0)
    first_time, first = timeline[0]
    assert isinstance(first, app.Attitude), "B first"
    assert first_time == 1.4, "§13.1: the first record about 1.4 s after power-up"
    gaps = {round(b2 - a2, 3) for (a2, _), (b2, _) in itertools.pairwise(timeline)}
    assert gaps == {0.06}, "records up to 14 bytes: 60 ms"
    b.receive(b"{Q:P}", 2.0)
    timeline = records(b, 2.0, 2.5)
    c_at = next(t for t, r in timeline if isinstance(r, app.ParamsRecord))
    after = next(t for t, _ in timeline if t > c_at)
    assert round(after - c_at, 3) == 0.08, "a pass with a C record: 80 ms"
    b.vehicle.heading = 181.0  # {B0:0:-179:100}$, 16 bytes: 65 ms
    timeline = records(b, 2.5, 3.0)
    lengths = {len(r.raw): round(t2 - t1, 3) for (t1, r), (t2, _) in itertools.pairwise(timeline)}
    assert lengths.get(16) == 0.065


def test_s13_a_read_during_a_c_record_is_lost() -> None:
    b = board()
    b.receive(b"{Q:P}", 2.0)
    timeline = records(b, 2.0, 2.2)
    c_at = next(t for t, r in timeline if isinstance(r, app.ParamsRecord))
    b2 = board()
    b2.receive(b"{Q:P}", 2.0)
    b2.poll(c_at + 0.01)
    b2.receive(b"{Q:P}", c_at + 0.01)  # the C record's 29 bytes take 30 ms
    later = records(b2, c_at + 0.01, c_at + 0.5)
    assert not any(isinstance(r, app.ParamsRecord) for _, r in later)
    assert any("lost" in n.text for n in b2.take_notes())


def test_s13_battery_unfloored_and_dead_until_1_9_s() -> None:
    b = board(centivolts=1000.0)
    timeline = records(b, 0, 2.3)
    batteries = [(t, r.battery) for t, r in timeline if isinstance(r, app.Attitude)]
    assert {v for t, v in batteries if t < 1.9} == {-740}
    assert {v for t, v in batteries if t >= 1.9} == {-73}, "(1000 − 1110) × 2/3, truncated"
    b = board()
    b.receive(b"JA", 0.5)
    b.poll(1.89)
    assert b.vehicle.vy == 0, "motors off until the battery reads"
    b.poll(2.0)
    assert b.vehicle.vy > 0


def test_s13_1_start_up_text_at_half_a_second() -> None:
    b = board()
    assert b.poll(0.499) == b""
    lines = b.poll(0.5).decode().split("\r\n")
    assert len(lines) == 11 and lines[-1] == ""
    assert lines[:2] == ["mpu_set_sensor complete ......"] * 2, "§13.1: twice"
    assert not any("mpu_dmp_init" in line for line in lines)
    assert b.poll(1.399) == b""


def test_sheet_profile_is_the_default_and_unchanged() -> None:
    b = Board()
    assert b.profile is SHEET
    first = records(b, 0, 0.0)[0][1]
    assert isinstance(first, app.Velocity)
