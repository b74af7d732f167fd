"""`appmode ros --chassis` in place of the vendor's driver, seen from the ROS-side peer
(tests/ros/peer.py): cmd_vel drives a simulated WHEELTEC car over its chassis port, odom
comes from its status frames, imu carries the IMU's own rates and accelerations,
battery_state its voltage, and silence ends with a zero frame on the board's recording."""

from __future__ import annotations

import time
from pathlib import Path
from statistics import median

import pytest

pytest.importorskip("zenoh", reason="the ros extra (eclipse-zenoh) is not installed")
pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")

from appmode.protocol import chassis
from appmode.testing.process import BoardProcess
from tests.ros import peer
from tests.ros.conftest import free_endpoint
from tests.support.processes import serving, stop_process

STOP = chassis.STOP.hex(" ").upper()


def sent(record: Path) -> list[str]:
    lines = record.read_text().splitlines() if record.exists() else []
    return [line.split(" c> ", 1)[1] for line in lines if " c> " in line]


TOPICS = {
    "appmode": ("/battery_state", "/imu", "base_link", "odom", "base_link"),
    "wheeltec": ("/PowerVoltage", "/imu/data_raw", "gyro_link", "odom_combined", "base_footprint"),
}


@pytest.mark.slow
@pytest.mark.parametrize("topics", list(TOPICS))
def test_ros_drives_a_wheeltec_car_and_publishes_what_its_status_says(
    tmp_path: Path, topics: str
) -> None:
    """As the vendor's driver: with `--topics wheeltec` its topic names, frames and
    PowerVoltage (std_msgs/Float32, volts), and no TF of its own."""
    power, imu_topic, imu_frame, odom_frame, base_frame = TOPICS[topics]
    profile = tmp_path / "quick.toml"
    profile.write_text(
        'name = "quick"\nlike = "wheeltec-mec"\n[chassis]\nkind = "mec"\nboot_ms = 500\n'
    )
    endpoint = free_endpoint()
    router = peer.router(endpoint)
    record = tmp_path / "board.transcript"
    board = BoardProcess("--pty", "--quiet", "--record", str(record), "--profile", str(profile))
    assert board.chassis is not None
    node, line = serving(
        "ros", board.chassis, "--chassis", "--profile", str(profile), "--connect", endpoint,
        "--topics", topics, data=tmp_path / "data",
    )  # fmt: skip
    ros = peer.session(endpoint)
    try:
        assert line.startswith("ros: node /appmode"), f"{line!r}: {stop_process(node)}"
        end = time.monotonic() + 15
        wanted = {"/odom", imu_topic, power, "/cmd_vel"}  # its tokens come in no one order:
        # a count of them was reached once before /odom's
        while not wanted <= (topic := {e.topic: e for e in peer.graph(ros)}).keys():
            if time.monotonic() > end:
                raise AssertionError(f"the graph holds {sorted(topic)}")
            time.sleep(0.2)
        odom, imu, battery = peer.Received(), peer.Received(), peer.Received()
        subscribers = [
            ros.declare_subscriber(topic[name].data_key, got.on_sample)
            for name, got in (("/odom", odom), (imu_topic, imu), (power, battery))
        ]
        assert ("/tf" in topic) == (topics == "appmode"), "the vendor's driver sends no TF"
        twist = peer.TwistPublisher(ros, topic["/cmd_vel"])
        start = time.monotonic()
        while time.monotonic() - start < 3.0:
            twist.publish(0.3, 0.5)
            time.sleep(0.05)
        for subscriber in subscribers:
            subscriber.undeclare()
        quiet = time.monotonic()
        while time.monotonic() - quiet < 5 and (not sent(record) or sent(record)[-1] != STOP):
            time.sleep(0.05)
        err = stop_process(node)
    finally:
        ros.close()
        stop_process(node)
        board.stop()
        router.close()
    assert "Traceback" not in err and "not sent" not in err, err
    # the median of the last 10 (a loaded machine may let cmd_vel lapse for a moment)
    moving = odom.messages("nav_msgs/msg/Odometry")[-10:]
    assert median(m.twist.twist.linear.x for m in moving) == pytest.approx(0.3, abs=0.03)
    assert median(m.twist.twist.angular.z for m in moving) == pytest.approx(0.5, abs=0.05)
    rates = imu.messages("sensor_msgs/msg/Imu")[-10:]
    assert median(m.angular_velocity.z for m in rates) == pytest.approx(0.5, abs=0.05)
    assert all(m.linear_acceleration.z == pytest.approx(9.8, abs=0.1) for m in rates)
    assert rates[-1].orientation_covariance[0] == -1, "no orientation: REP 145's −1"
    if topics == "wheeltec":
        volts = [m.data for m in battery.messages("std_msgs/msg/Float32")]
    else:
        volts = [m.voltage for m in battery.messages("sensor_msgs/msg/BatteryState")]
    assert volts and all(11.5 <= v <= 12.61 for v in volts), volts[-3:]
    assert moving[-1].header.frame_id == odom_frame and moving[-1].child_frame_id == base_frame
    assert rates[-1].header.frame_id == imu_frame
    frames = sent(record)
    assert chassis.command(chassis.Command(300, 0, 500).twist).hex(" ").upper() in frames
    assert frames[-1] == STOP, "silence ends with the zero frame on the board's recording"
