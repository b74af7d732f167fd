"""The twist, the session's one motion language in SI units: what each port makes of it,
what the records say of it (the car's twist sensed), and that it lasts only while its
source repeats it — judged on the simulated board's own records."""

from __future__ import annotations

import math
import time
from dataclasses import astuple
from pathlib import Path

import pytest

from appmode.ports.target import parse_target
from appmode.protocol.layouts import Layout
from appmode.protocol.odometry import Odometry
from appmode.protocol.params import DriveType
from appmode.protocol.profile_file import shipped
from appmode.protocol.sensed import Sensing, yaw_rate
from appmode.protocol.twist import LIMIT, BadTwist, Twist
from appmode.session.app.velocity import letter_for
from appmode.session.base import BaseSession
from appmode.session.control.velocity import frame_fields
from appmode.session.hold import TWIST, HoldToDrive
from tests.support.processes import BoardProcess, run, sent_lines
from tests.support.sessions import session as open_board

SI = (0.001, 0.001)


def test_dead_reckoning_integrates_twists() -> None:
    odometry = Odometry()
    for step in range(11):  # 0.5 m/s forward for a second, reports every 0.1 s
        pose = odometry.step(step / 10, Twist(0.5))
    assert pose.x == pytest.approx(0.5) and pose.y == pytest.approx(0.0)
    assert pose.forward == pytest.approx(0.5) and odometry.distance == pytest.approx(0.5)
    for step in range(11, 22):  # a quarter turn to the right
        pose = odometry.step(step / 10, Twist(turn=-1.571))
    assert pose.yaw == pytest.approx(-math.pi / 2, abs=0.1) and pose.turn < 0
    odometry.step(5.0, Twist(left=-0.3))  # after a gap in the telemetry: no step across it
    assert odometry.pose.x == pytest.approx(pose.x) and odometry.pose.left == -0.3
    assert odometry.variance > 1e-4


def test_a_twist_in_board_units_and_back() -> None:
    twist = Twist(0.3, 0.1, 0.5)
    assert twist.units(SI) == pytest.approx((-100, 300, -500))
    assert astuple(Twist.from_units(-100, 300, -500, SI)) == pytest.approx(astuple(twist))
    assert Twist(0.001, 0.0, 0.004).still and not Twist(0.0, 0.0, 0.006).still


def test_a_twist_from_outside_is_a_number_and_within_reason() -> None:
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(BadTwist, match="each part must be a number"):
            Twist.checked(bad, 0.0, 0.0)
    with pytest.raises(BadTwist, match="no car's"):
        Twist.checked(1e307, 0.0, 0.0)
    fast = Twist.checked(LIMIT, -LIMIT, 70.0)  # within reason: each port clamps it
    assert (fast.forward, fast.left, fast.turn) == (LIMIT, -LIMIT, 70.0)
    # the frame's fields are clamped before they are rounded: no number overflows
    assert frame_fields(Twist(1e300), DriveType.MECANUM, SI, None)["y"] == 0xFFFF
    assert frame_fields(Twist(turn=-1e300), DriveType.DIFF, SI, 500)["z"] == 1000


def test_a_twist_as_velocity_frames() -> None:
    omni = frame_fields(Twist(0.3, 0.1, 0.5), DriveType.MECANUM, SI, None)
    assert omni == {"x": -100, "y": 300, "z": -500}
    diff = frame_fields(Twist(0.25, 0.0, 0.25), DriveType.DIFF, SI, 500)
    assert diff == {"y": 500, "z": -500}
    gyro = frame_fields(Twist(0.25, 0, 0.25), DriveType.DIFF_GYRO, SI, 500)
    assert gyro == {"left": 0, "right": 1000}
    assert frame_fields(Twist(100.0), DriveType.DIFF, SI, 500) == {"y": 1000, "z": 0}  # capped
    with pytest.raises(ValueError, match="max_speed"):
        frame_fields(Twist(0.1), DriveType.DIFF, SI, None)


def test_a_twist_as_the_app_port_s_nearest_direction() -> None:
    letters = {
        (1, 0): "A", (1, 1): "H", (0, 1): "G", (-1, 1): "F",
        (-1, 0): "E", (-1, -1): "D", (0, -1): "C", (1, -1): "B",
    }  # fmt: skip
    for (forward, left), letter in letters.items():
        found = letter_for(Twist(0.2 * forward, 0.2 * left), DriveType.OMNI, SI)
        assert found is not None and (found.page, found.letter) == ("J", letter)
        assert found.speed == 200  # a diagonal drives each of its axes at max_speed
    turn = letter_for(Twist(turn=-0.8), DriveType.OMNI, SI)
    assert turn is not None and (turn.page, turn.letter, turn.speed) == ("K", "C", 800)
    diff = letter_for(Twist(turn=0.8), DriveType.DIFF, SI)
    assert diff is not None and (diff.page, diff.letter) == ("J", "G")
    assert letter_for(Twist(0.001, 0, 0.001), DriveType.OMNI, SI) is None


def test_magnitudes_take_the_signs_in_force_and_the_turn_comes_from_the_yaw() -> None:
    sheet, mini = (Sensing(Layout(name, shipped(name))) for name in ("sheet", "minibalance"))
    assert sheet.gap is None and not sheet.needs_signs
    sheet_twist = sheet.twist((-100, 300, -500, 0), None, None)  # z: π mrad/s a unit
    assert astuple(sheet_twist) == pytest.approx(astuple(Twist(0.3, 0.1, 0.5 * math.pi)))
    assert mini.gap is None and mini.needs_signs and mini.turn_from_yaw
    assert mini.twist((70, 210, 90, 0), None, 0.0) is None  # signs unknown: no twist
    twist = mini.twist((70, 210, 90, 0), (-1.0, 1.0, 0.0), 0.0)
    assert astuple(twist) == pytest.approx(astuple(Twist(0.3, 0.1, 0.0)))
    turning = mini.twist((0, 0, 90, 0), (0.0, 0.0, 1.0), math.degrees(0.5))
    assert astuple(turning) == pytest.approx(astuple(Twist(turn=-0.5)))  # the yaw: clockwise
    balance = Sensing(Layout("balance", shipped("balance")))
    assert balance.gap is not None and "no velocity of x and y" in balance.gap


def test_the_yaw_rate_unwraps_across_180_degrees() -> None:
    points = [(0.0, 170.0), (0.1, 179.0), (0.2, -172.0), (0.3, -163.0)]
    assert yaw_rate(points, 0.3) == pytest.approx(90.0)
    assert yaw_rate(points[:1], 0.3) is None
    assert yaw_rate(points, 5.0) is None  # nothing in the window before it


def test_a_twist_never_latches() -> None:
    hold = HoldToDrive(first_timeout=0.5, repeat_timeout=0.2, latched=True)
    hold.press("A", 0.0)
    assert hold.late(10.0) is None  # a latched key stays
    hold.press(TWIST, 10.0)
    assert hold.late(10.6) == pytest.approx(0.1) and hold.release_due(10.6)


def drive(session: BaseSession, twist: Twist, seconds: float) -> list[tuple[float, Twist]]:
    """Repeat `twist` every 50 ms for `seconds` (as a cmd_vel at 20 Hz): the sensed twists."""
    start = session.now()
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        session.tick()
        session.move(twist)
        time.sleep(0.05)
    return session.sensed(start)


def settled(sensed: list[tuple[float, Twist]], after: float) -> Twist:
    """The mean of the sensed twists from `after` seconds into the run."""
    kept = [twist for at, twist in sensed if at >= sensed[0][0] + after]
    assert kept, sensed
    n = len(kept)
    return Twist(
        sum(t.forward for t in kept) / n,
        sum(t.left for t in kept) / n,
        sum(t.turn for t in kept) / n,
    )


@pytest.mark.slow
@pytest.mark.parametrize(("uart2", "profile"), [(False, None), (True, None), (True, "minibalance")])
def test_every_port_drives_a_twist_and_senses_it(uart2: bool, profile: str | None) -> None:
    url = "sim://" if profile is None else f"sim://?profile={profile}"
    hold = HoldToDrive(first_timeout=0.3, repeat_timeout=0.3)
    url2 = parse_target(url).for_uart2().url if uart2 else None
    session = open_board(url, hold, url2=url2)  # both ports, as `appmode ros sim://` has
    try:
        session.start()
        drive(session, Twist(), 1.5)  # the parameters read, the boot over
        assert session.odometry_gap() is None
        forward = settled(drive(session, Twist(0.3), 2.5), 1.0)
        assert forward.forward == pytest.approx(0.3, abs=0.09), forward
        assert abs(forward.left) < 0.05 and abs(forward.turn) < 0.1, forward
        turn = settled(drive(session, Twist(turn=0.5), 2.5), 1.2)
        assert turn.turn == pytest.approx(0.5, abs=0.2), turn
        assert abs(turn.forward) < 0.09 and abs(turn.left) < 0.09, turn
        stopped = session.now()
        end = time.monotonic() + 2.0  # no twist comes: the hold lapses, the car stops
        while time.monotonic() < end and session.moving:
            session.tick()
            time.sleep(0.01)
        assert not session.moving and session.now() - stopped < 0.6
    finally:
        session.close()


@pytest.mark.parametrize("uart2", [False, True])
def test_a_script_s_twist_drives_either_port_and_the_session_ends_with_the_stop(
    tmp_path: Path, uart2: bool
) -> None:
    """`twist` in a script, judged on the board's recording: the APP port's nearest
    direction at the speed asked, or the control port's velocity frame; the stop last."""
    record = tmp_path / "board.transcript"
    board = BoardProcess("--pty", "--quiet", "--record", str(record))
    script = b"twist 0.3\nwait 0.6\ntwist 0 0 0.5\nwait 0.6\ntwist nan\n"
    try:
        args = (board.url, board.uart2) if uart2 else (board.url,)
        done = run("drive", *args, stdin=script)
    finally:
        board.stop()
    assert done.returncode == 1, done.stderr  # the NaN is refused, the script stops there
    assert "a twist of nan, 0.0, 0.0: each part must be a number" in done.stderr
    lines = record.read_text().splitlines()
    if uart2:
        frames = [line.split(" 2> ", 1)[1] for line in lines if " 2> " in line]
        assert "FF FE 01 00 00 01 2C 00 00 00" in frames  # y = 300: 0.3 m/s
        assert "FF FE 01 00 00 00 00 00 9F 01" in frames  # z = 159 anticlockwise (bit 0)
        assert frames[-1] == "FF FE 01 00 00 00 00 00 00 00"
    else:
        sent = sent_lines(record)
        assert sent.index("{0:300}") < sent.index("A") < sent.index("K")
        assert sent.index("K") < sent.index("{0:159}") < sent.index("G")
        assert sent[-1] == "Z"


def test_a_twist_that_changes_speed_on_a_car_every_frame_stops_still_lapses() -> None:
    """minibalance stops at every frame (§13): a new speed's `{0:N}` stops the car the
    twist drove. A twist given once (as typed) leaves no motion that outlives its hold."""
    session = open_board("sim://?profile=minibalance", HoldToDrive(0.3, 0.3))
    try:
        session.start()
        drive(session, Twist(), 1.5)
        drive(session, Twist(0.3), 1.0)
        session.move(Twist(0.5))  # once, as a typed twist: its frame stops the car
        stopped = session.now()
        end = time.monotonic() + 3.0
        while time.monotonic() < end and (session.now() - stopped < 0.5 or session.moving):
            session.tick()
            time.sleep(0.01)
        assert not session.moving and session.now() - stopped < 0.9
    finally:
        session.close()
