"""The minibalance profile against docs/protocol.md §13.1 (the firmware measured again):
each case played on the board's wires, paced as the real lines are."""

from __future__ import annotations

from appmode.board.firmware import Board
from appmode.board.profiles import MINIBALANCE
from appmode.line.wire import APP, UART2, Wire
from appmode.protocol import app, app_decoders

ON = 2.0
"""After the dead time (the battery reads 1.9 s after power-up)."""
STEP = 0.001

Script = list[tuple[float, str, bytes]]


def play(script: Script, until: float) -> tuple[Board, list[tuple[float, app.Record]], bytes]:
    """Send each (time, port, bytes) on a fresh board's paced wires; the APP port's records
    with the time each came, and all UART2 carried."""
    wire = Wire(Board(profile=MINIBALANCE))
    decoder = app_decoders.BoardDecoder()
    out: list[tuple[float, app.Record]] = []
    uart2 = b""
    pending = sorted(script, key=lambda item: item[0])
    t = 0.0
    while t <= until + 1e-9:
        while pending and pending[0][0] <= t + 1e-9:
            _, port, data = pending.pop(0)
            wire.write(data, t, port)
        out += [(t, e) for e in decoder.feed(wire.pump(t, APP)) if isinstance(e, app.RECORDS)]
        uart2 += wire.pump(t, UART2)
        t = round(t + STEP, 3)
    wire.board.advance(until)  # the board runs its ticks when it is next used
    return wire.board, out, uart2


def a_after(records: list[tuple[float, app.Record]], t: float) -> list[app.Velocity]:
    return [r for when, r in records if when > t and isinstance(r, app.Velocity)]


def test_a_negative_max_speed_holds_every_axis_and_the_car_turns() -> None:
    board, records, _ = play([(ON, APP, b"{0:-5}")], ON + 1.0)
    assert board.params[0] == -25
    shown = {(r.x, r.y) for r in a_after(records, ON + 0.2)}
    assert shown == {(17, 17)}, "|−25 · 0.7| at rest"
    assert board.vehicle.vz == -25 and board.vehicle.heading != 0


def test_lowering_max_speed_while_moving_cuts_the_speed_at_the_next_tick() -> None:
    script = [(ON, APP, b"{0:300}"), (ON + 0.1, APP, b"JA"), (ON + 1.6, APP, b"{0:20}")]
    _, records, _ = play(script, ON + 2.0)
    before = a_after(records, ON + 1.4)[0]
    assert before.y > 40
    assert a_after(records, ON + 1.62)[0].y <= 14, "clamped to 20, not coasting from 75"


def test_a_set_value_is_summed_from_its_last_digit() -> None:
    _, records, _ = play([(ON, APP, b"{0:123456789}{Q:P}")], ON + 0.4)
    values = [r.values for _, r in records if isinstance(r, app.ParamsRecord)]
    assert values and values[0][0] == 123456784


def test_the_a_record_scales_in_float32() -> None:
    script = [(ON, APP, b"{0:90}"), (ON + 0.1, APP, b"JA")]
    _, records, _ = play(script, ON + 3.1)
    assert a_after(records, ON + 3.0)[0].y == 63, "90 · 0.7f is 63 in float32, 62.999… in double"


def test_a_rotation_that_ended_stops_at_once_on_either_page() -> None:
    """§13.1 on the direction page; §13.2 on the button page (where §13.1 had it coast)."""
    script = [(ON, APP, b"KC"), (ON + 1.0, APP, b"B")]
    board, _, _ = play(script, ON + 0.999)
    assert board.vehicle.vz == 30
    board, _, _ = play(script, ON + 1.011)
    assert board.vehicle.vz == 0, "on the button page z is 0 at the next tick"
    script = [(ON, APP, b"KC"), (ON + 1.0, APP, b"JA"), (ON + 1.1, APP, b"Z")]
    board, _, _ = play(script, ON + 1.111)
    assert board.vehicle.vz == 0


def test_s13_2_a_frame_on_the_button_page_ends_the_rotation_and_g_starts_it_from_0() -> None:
    """§13.2's minimal case: KG, `{3:{}` at 0.560, G at 0.717, Z at 1.561 (the commanded
    z, tick by tick: the frame's first byte zeroes it, G ramps it from 0, Z zeroes it)."""
    script = [(ON, APP, b"KG"), (ON + 0.56, APP, b"{3:{}"), (ON + 0.717, APP, b"G")]
    script.append((ON + 1.561, APP, b"Z"))
    board, _, _ = play(script, ON + 0.559)
    assert board.vehicle.vz < 0, "rotating left"
    board, _, _ = play(script, ON + 0.571)
    assert board.vehicle.vz == 0, "the frame's first byte cleared the rotation"
    assert board.params[3] == 75, "`{3:{}` sets position_ki to 0x7B − 0x30"
    board, _, _ = play(script, ON + 0.731)
    assert -2 < board.vehicle.vz < 0, "G ramps z from 0, one step a tick"
    board, _, _ = play(script, ON + 1.571)
    assert board.vehicle.vz == 0, "Z stops it within one tick"


def test_a_uart2_velocity_is_taken_unclamped_and_without_a_ramp() -> None:
    frame = bytes.fromhex("FF FE 01 00 00 00 C8 00 00 00 00")
    board, records, _ = play([(ON, UART2, frame)], ON + 0.2)
    assert board.params[0] == 30 and board.uart2_control
    assert a_after(records, ON)[0].y == 140, "200 · 0.7 in the first record, max_speed 30"


def test_uart2_motor_frames_move_nothing() -> None:
    board, _, _ = play([(ON, UART2, bytes.fromhex("FF FE 02 64 64 64 00 00 00 00 00"))], ON + 1)
    assert board.uart2_control
    assert (board.vehicle.vx, board.vehicle.vy, board.vehicle.vz) == (0, 0, 0)


def test_the_take_over_freezes_the_motion() -> None:
    script = [(ON, APP, b"{0:300}"), (ON + 0.1, APP, b"JA"), (ON + 1.1, UART2, bytes(11))]
    board, records, _ = play(script, ON + 3.0)
    assert board.uart2_control
    assert {r.y for r in a_after(records, ON + 1.2)} == {35}, "50 units, kept"


def test_the_8_bytes_after_a_header_are_a_frame_whatever_they_hold() -> None:
    data = bytes.fromhex("FF FE 05 FF FE 01 00 00 00 14 00 00 00")
    board, _, _ = play([(ON, UART2, data)], ON + 1)
    assert board.uart2_control
    assert board.vehicle.vy == 0, "the header inside the mode-05 frame starts nothing"


def test_a_frame_is_taken_only_when_the_line_pauses() -> None:
    first = bytes.fromhex("FF FE 01 00 00 00 64 00 00 00")
    second = bytes.fromhex("FF FE 01 00 00 00 32 00 00 00")
    script = [(ON, UART2, bytes(11)), (ON + 0.1, UART2, first + second[:3])]
    board, _, _ = play(script, ON + 0.5)
    assert board.vehicle.vy == 0, "a frame under way: the first is not taken"
    board, _, _ = play([*script, (ON + 0.5, UART2, second[3:])], ON + 0.6)
    assert board.vehicle.vy == 50, "the last frame, once the line pauses"


def test_a_header_alone_is_no_frame_under_way() -> None:
    """Usart_Flag is set by the byte after `FF FE`: a tick between the header and that
    byte takes the frame before it (meca_base usartx.c)."""
    first = bytes.fromhex("FF FE 01 00 00 00 64 00 00 00")
    script = [(ON, UART2, bytes(11)), (ON + 0.1, UART2, first + b"\xff\xfe")]
    board, _, _ = play(script, ON + 0.3)
    assert board.vehicle.vy == 100


def y_by_tick(data: bytes, ticks: int) -> list[float]:
    """The board model's commanded y at each 10 ms control tick after `data` came on
    UART2 (back to back, no pause), once the board runs."""
    board = Board(profile=MINIBALANCE)
    board.advance(ON)
    board.receive_uart2(data, ON)
    ys: list[float] = []
    for tick in range(1, ticks + 1):
        board.advance(ON + tick * 0.01)
        ys.append(board.vehicle.vy)
    return ys


def test_the_header_is_the_last_two_bytes_a_frames_own_included() -> None:
    """§13.3's minimal case: the first frame's data ends in `FF FE`, so the byte after it
    starts the second, the zero frame, and only the last frame counts: y 0 throughout."""
    data = bytes.fromhex("FF FE 01 00 20 74 60 AE FF FE 01 00 00 00 00 00 00 00")
    assert y_by_tick(data, 100) == [0] * 100
    board = Board(profile=MINIBALANCE)
    board.advance(ON)
    board.receive_uart2(data, ON)
    board.advance(ON + 1.0)
    assert (board.vehicle.vx, board.vehicle.vy, board.vehicle.vz) == (0, 0, 0)
    assert board.vehicle.heading == 0, "no turn either"


def test_a_motor_frame_after_the_same_prefix_moves_nothing() -> None:
    data = bytes.fromhex("FF FE 01 00 20 74 60 AE FF FE 02 D9 82 26 00 00 00 07")
    board = Board(profile=MINIBALANCE)
    board.advance(ON)
    board.receive_uart2(data, ON)
    board.advance(ON + 1.0)
    assert board.vehicle.vx == 0 and board.vehicle.vy == 0


def test_of_two_frames_in_one_tick_only_the_last_counts() -> None:
    go = bytes.fromhex("FF FE 01 00 00 00 64 00 00 00")
    assert y_by_tick(bytes(11) + go + bytes.fromhex("FF FE 01 00 00 00 32 00 00 00"), 5) == [50] * 5
    assert y_by_tick(bytes(11) + go, 5) == [100] * 5


def test_with_bytes_between_the_two_frames_both_are_frames() -> None:
    """§13.3: `… 60 AE 00 00 00 00 FF FE 01 …`: the second frame is found by its own
    header, and it is the last one."""
    data = bytes.fromhex("FF FE 01 00 20 74 60 AE 00 00 00 00 FF FE 01 00 00 00 14 00 00 00")
    board = Board(profile=MINIBALANCE)
    board.advance(ON)
    board.receive_uart2(data, ON)
    board.advance(ON + 0.5)
    assert board.vehicle.vy == 20


def test_a_frame_before_the_take_over_counts_only_if_it_is_the_last() -> None:
    velocity = bytes.fromhex("FF FE 01 00 00 00 64 00 00 00")
    motors = bytes.fromhex("FF FE 02 10 10 10 00 00 00 00")
    board, _, _ = play([(ON, UART2, velocity + b"\0")], ON + 0.1)
    assert board.vehicle.vy == 100
    board, _, _ = play([(ON, UART2, velocity), (ON + 0.1, UART2, motors)], ON + 0.3)
    assert board.uart2_control and board.vehicle.vy == 0


def test_uart2_carries_a_burst_after_each_app_record() -> None:
    _, records, uart2 = play([], ON)
    assert uart2 == b"\xff\xfe\x00" * len(records), "FF FE and the gyro's low byte, at rest"


def test_a_negative_speed_setting_commands_every_axis_each_tick_whatever_is_held() -> None:
    """§13.3's open note, compared on the commanded z tick by tick: `{0:-596}` sets
    −2404 (the `-` is −3 · 1000), and each tick's clamp (`v < −max`, then `v > max`)
    leaves every axis at −2404 while rotating with `G` and after `H`: the yaw a peer
    reports at that rate aliases (±180° wraps between records), the command does not."""
    board = Board(profile=MINIBALANCE)
    board.advance(ON)
    board.receive(b"KG", ON)
    board.advance(ON + 0.3)
    assert board.vehicle.vz < 0
    board.receive(b"{0:-596}", ON + 0.3)
    held: set[tuple[float, float, float]] = set()
    for tick in range(1, 60):
        if tick == 30:
            board.receive(b"H", ON + 0.3 + tick * 0.01)
        board.advance(ON + 0.3 + tick * 0.01 + 0.001)
        if tick > 1:
            held.add((board.vehicle.vx, board.vehicle.vy, board.vehicle.vz))
    assert board.params[0] == -2404
    assert held == {(-2404, -2404, -2404)}
