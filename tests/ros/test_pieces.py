"""The ROS node's pure parts: names, and the command line's refusals (one line, exit 2).
What a cmd_vel asks of each port is the session's twist: tests/session/test_twist.py."""

from __future__ import annotations

import pytest

from appmode.ros.graph import BadName, namespace, node_name
from tests.support.processes import run


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
