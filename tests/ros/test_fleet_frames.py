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
from tests.ros.conftest import free_endpoint
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


def test_a_late_subscriber_gets_tf_static_as_rmw_zenoh_serves_it(tmp_path: Path) -> None:
    """Issue 77.2: the fixed frame on tf_static, transient local as robot_state_publisher
    has it — a subscriber that comes later, declared as rmw_zenoh declares a transient
    local one (rmw_subscription_data.cpp: history, late publishers detected), gets it."""
    import zenoh.ext

    endpoint = free_endpoint()
    router = peer.router(endpoint)
    ros = peer.session(endpoint)
    node, line = serving(
        "ros", "sim://", "--connect", endpoint, "--frame-prefix", "car1/", data=tmp_path / "d"
    )
    got = peer.Received()
    try:
        assert line.startswith("ros: node /appmode"), f"{line!r}: {stop_process(node)}"
        end = time.monotonic() + 15
        found = peer.graph(ros)
        while not any(e.topic == "/tf_static" for e in found):
            assert time.monotonic() < end, found
            time.sleep(0.2)
            found = peer.graph(ros)
        static = next(e for e in found if e.topic == "/tf_static")
        assert static.qos.startswith(":1:,1:"), static.qos  # transient local, depth 1
        time.sleep(1.0)  # later than the node's one sample
        history = zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=1)
        subscriber = zenoh.ext.declare_advanced_subscriber(
            ros, static.data_key, got.on_sample, history=history, subscriber_detection=True
        )
        end = time.monotonic() + 5
        while not got.payloads and time.monotonic() < end:
            time.sleep(0.1)
        subscriber.undeclare()
    finally:
        err = stop_process(node)
        ros.close()
        router.close()
    assert "Traceback" not in err, err
    (message,) = got.messages("tf2_msgs/msg/TFMessage")
    (transform,) = message.transforms
    assert (transform.header.frame_id, transform.child_frame_id) == (
        "car1/base_link",
        "car1/base_footprint",
    )
