"""Issue 77.2: two namespaced cars on one domain, seen from the ROS-side peer: each puts
its transforms on its namespace's own tf (where a namespaced Nav2, which remaps /tf to
tf, listens), so neither's tree reaches the other's; `--frame-prefix`, `--odom-frame` and
`--base-frame` name the frames."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

pytest.importorskip("zenoh", reason="the ros extra (eclipse-zenoh) is not installed")
pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")

from tests.ros import peer
from tests.ros.test_node import free_endpoint
from tests.support.processes import serving, stop_process


def test_two_namespaced_cars_keep_their_transforms_apart(tmp_path: Path) -> None:
    endpoint = free_endpoint()
    router = peer.router(endpoint)
    nodes = []
    ros = peer.session(endpoint)
    try:
        for name, extra in (
            ("car1", ("--frame-prefix", "car1/")),
            ("car2", ("--odom-frame", "world", "--base-frame", "chassis")),
        ):
            node, line = serving(
                "ros", "sim://?profile=wheeltec-mec", "--chassis", "--namespace", f"/{name}",
                "--connect", endpoint, *extra, data=tmp_path / name,
            )  # fmt: skip
            nodes.append(node)
            assert line.startswith(f"ros: node /{name}/appmode"), f"{line!r}: {stop_process(node)}"
        end = time.monotonic() + 15
        while len(entities := peer.graph(ros)) < 14 and time.monotonic() < end:
            time.sleep(0.2)
        topics = {e.topic for e in entities}
        assert {"/car1/tf", "/car2/tf", "/car1/odom", "/car2/odom"} <= topics, topics
        assert "/tf" not in topics, "no car's tree on the shared /tf"
        by_topic = {e.topic: e for e in entities}
        got = {name: peer.Received() for name in ("car1", "car2")}
        subscribers = [
            ros.declare_subscriber(by_topic[f"/{name}/odom"].data_key, got[name].on_sample)
            for name in got
        ]
        end = time.monotonic() + 5
        while time.monotonic() < end and not all(g.payloads for g in got.values()):
            time.sleep(0.1)
        for subscriber in subscribers:
            subscriber.undeclare()
    finally:
        errors = [stop_process(node) for node in nodes]
        ros.close()
        router.close()
    assert all("Traceback" not in err for err in errors), errors
    one = got["car1"].messages("nav_msgs/msg/Odometry")[-1]
    two = got["car2"].messages("nav_msgs/msg/Odometry")[-1]
    assert (one.header.frame_id, one.child_frame_id) == ("car1/odom", "car1/base_link")
    assert (two.header.frame_id, two.child_frame_id) == ("world", "chassis")
