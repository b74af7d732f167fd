"""Issue 77.6: the guide's two machines, as network namespaces: the car runs `appmode ros
--namespace robot1 --router --connect tcp/CAR:7447` on its board; the laptop runs a
router connected to the car's and a ROS context with rmw_zenoh's default session config
(tests/ros/laptop.py), which finds the node, drives it with cmd_vel and reads odom —
judged on the board's recording, which ends with the stop once cmd_vel is silent. (A
node that joins the laptop's router alone is not seen by the laptop's peers, which
listen on localhost only: the guide no longer says to.)"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("zenoh", reason="the ros extra (eclipse-zenoh) is not installed")
pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")

from tests.support.netns import lan, why_not
from tests.support.processes import ROOT, sent_lines

WHY = why_not()
pytestmark = pytest.mark.skipif(WHY is not None, reason=f"no network namespaces: {WHY}")


@pytest.mark.slow
def test_the_laptop_drives_the_car_through_its_router(tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    with lan("car", "laptop") as machines:
        car, laptop = machines["car"], machines["laptop"]
        board = car.popen("board", "--pty", "--quiet", "--record", str(record))
        assert board.stdout is not None
        port = board.stdout.readline().removeprefix("port: ").strip()
        node = car.popen(
            "ros", port, "--namespace", "robot1", "--router", "--connect",
            f"tcp/{car.address}:7447",
        )  # fmt: skip
        time.sleep(2.0)  # the car's router first
        laptop_side = subprocess.Popen(
            laptop.command(sys.executable, "-m", "tests.ros.laptop", car.address, "/robot1", "3"),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        try:
            out, err = laptop_side.communicate(timeout=60)
            time.sleep(1.5)  # cmd_vel silent: the node stops the car
        finally:
            node.terminate()
            node_err = node.communicate(timeout=15)[1]
            board.terminate()
            board.communicate(timeout=15)
    seen = json.loads(out.strip().splitlines()[-1]) if out.strip() else {}
    assert "/robot1/cmd_vel" in seen.get("topics", []), (seen, err, node_err)
    assert "/robot1/tf" in seen["topics"] and "/tf" not in seen["topics"]
    assert seen["forward"] and max(seen["forward"]) == pytest.approx(0.3, abs=0.09), seen
    sent = sent_lines(record)
    assert "A" in sent and sent[-1] == "Z", sent[-6:]
