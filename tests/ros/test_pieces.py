"""The ROS node's pure parts: dead reckoning, what a cmd_vel asks of each port, and the
command line's refusals (one line, exit 2)."""

from __future__ import annotations

import math

import pytest

from appmode.protocol.odometry import Odometry
from appmode.protocol.params import DriveType
from appmode.ros.command import frame_fields, letter_for
from appmode.ros.graph import BadName, namespace, node_name
from tests.support.processes import run

SI = (0.001, 0.001)


def test_dead_reckoning_integrates_the_board_s_velocity_in_rep_103_axes() -> None:
    odometry = Odometry(*SI)
    for step in range(11):  # y = 500 mm/s forward for a second, records every 0.1 s
        pose = odometry.step(step / 10, 0, 500, 0)
    assert pose.x == pytest.approx(0.5) and pose.y == pytest.approx(0.0)
    assert pose.forward == pytest.approx(0.5) and odometry.distance == pytest.approx(0.5)
    for step in range(11, 22):  # z = 1571 mrad/s clockwise: a quarter turn to the right
        pose = odometry.step(step / 10, 0, 0, 1571)
    assert pose.yaw == pytest.approx(-math.pi / 2, abs=0.1) and pose.turn < 0
    odometry.step(5.0, 300, 0, 0)  # after a gap in the telemetry: no step across it
    assert odometry.pose.x == pytest.approx(pose.x) and odometry.pose.left == -0.3
    assert odometry.variance > 1e-4


def test_a_cmd_vel_as_velocity_frames() -> None:
    omni = frame_fields(0.3, 0.1, 0.5, DriveType.MECANUM, SI, None)
    assert omni == {"x": -100, "y": 300, "z": -500}
    diff = frame_fields(0.25, 0.0, 0.25, DriveType.DIFF, SI, 500)
    assert diff == {"y": 500, "z": -500}
    assert frame_fields(0.25, 0, 0.25, DriveType.DIFF_GYRO, SI, 500) == {"left": 0, "right": 1000}
    assert frame_fields(100.0, 0, 0, DriveType.DIFF, SI, 500) == {"y": 1000, "z": 0}  # capped
    with pytest.raises(ValueError, match="max_speed"):
        frame_fields(0.1, 0, 0, DriveType.DIFF, SI, None)


def test_a_cmd_vel_as_the_app_port_s_nearest_direction() -> None:
    letters = {
        (1, 0): "A", (1, 1): "H", (0, 1): "G", (-1, 1): "F",
        (-1, 0): "E", (-1, -1): "D", (0, -1): "C", (1, -1): "B",
    }  # fmt: skip
    for (forward, left), letter in letters.items():
        found = letter_for(0.2 * forward, 0.2 * left, 0.0, DriveType.OMNI, SI)
        assert found is not None and (found.page, found.letter) == ("J", letter)
    turn = letter_for(0, 0, -0.8, DriveType.OMNI, SI)
    assert turn is not None and (turn.page, turn.letter, turn.speed) == ("K", "C", 800)
    diff = letter_for(0, 0, 0.8, DriveType.DIFF, SI)
    assert diff is not None and (diff.page, diff.letter) == ("J", "G")
    assert letter_for(0.001, 0, 0.001, DriveType.OMNI, SI) is None


def test_names_ros_would_not_take_are_refused() -> None:
    assert namespace("robot1") == namespace("/robot1/") == "/robot1"
    assert namespace("") == "/"
    for bad in ("robot 1", "1robot", "a/b-c"):
        with pytest.raises(BadName):
            namespace(bad)
    with pytest.raises(BadName):
        node_name("my-node")


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (("--namespace", "robot 1"), "namespace 'robot 1'"),
        (("--domain", "300"), "not a ROS domain"),
        (("--cmd-vel-timeout", "0"), "--cmd-vel-timeout"),
        (("--connect", "tcp/127.0.0.1:9"), "no Zenoh router at tcp/127.0.0.1:9"),
    ],
)
def test_the_command_line_s_refusals_are_one_line(args: tuple[str, ...], said: str) -> None:
    pytest.importorskip("zenoh")
    done = run("ros", "sim://", *args, timeout=60)
    lines = done.stderr.strip().splitlines()  # argparse's usage, then the error's line
    assert done.returncode == 2 and said in lines[-1], done.stderr
    assert not [line for line in lines if "error" in line][1:] and "Traceback" not in done.stderr
