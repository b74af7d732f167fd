"""The car's parameters from ROS 2 (issue 77.4), called as rmw_zenoh's clients call
(tests/ros/peer.py): `ros2 param list`, `get`, `describe` and `set` — a set reaches the
board, judged on its own recording, and is answered once it reads back — the refusals
rclcpp would give, `~/save`, and the node's lines on /rosout."""

from __future__ import annotations

import time

import pytest

pytest.importorskip("zenoh", reason="the ros extra (eclipse-zenoh) is not installed")
pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")

from tests.ros import peer
from tests.ros.conftest import Car

# as `ros2 service info -v` prints them on Jazzy (any rclcpp node's), and
# rmw_zenoh's docs' AddTwoInts hash, reproduced the same way in test_vectors.py
LIST_PARAMETERS = "RIHS01_3e6062bfbb27bfb8730d4cef2558221f51a11646d78e7bb30a1e83afac3aad9d"
MAX_SPEED = 800


def services(car: Car) -> dict[str, peer.Entity]:
    """The node's services by name, once its tokens (eight topics, seven services) show."""
    return {e.topic: e for e in car.entities(16) if e.kind == "SS"}


def client(car: Car, name: str, service: str) -> peer.ServiceClient:
    return peer.ServiceClient(car.ros, services(car)[f"/appmode/{name}"], service)


def test_the_parameter_services_are_rclcpp_s(car: Car) -> None:
    found = services(car)
    assert sorted(found) == [
        "/appmode/describe_parameters",
        "/appmode/get_parameter_types",
        "/appmode/get_parameters",
        "/appmode/list_parameters",
        "/appmode/save",
        "/appmode/set_parameters",
        "/appmode/set_parameters_atomically",
    ]
    listing = found["/appmode/list_parameters"]
    assert listing.type_name == "rcl_interfaces::srv::dds_::ListParameters_"
    assert listing.type_hash == LIST_PARAMETERS
    assert listing.qos == "::,1000:,:,:,,"  # rclcpp's parameter services: depth 1000
    assert found["/appmode/save"].type_name == "std_srvs::srv::dds_::Trigger_"


def test_list_get_and_describe(car: Car) -> None:
    listed, _ = client(car, "list_parameters", "rcl_interfaces/srv/ListParameters").call(
        prefixes=[], depth=0
    )
    assert "max_speed" in listed.result.names and len(listed.result.names) == 9
    got, attached = client(car, "get_parameters", "rcl_interfaces/srv/GetParameters").call(
        names=["max_speed", "no_such"]
    )
    assert attached[0] == 1 and attached[2] == peer.ServiceClient.GID, "the request's own"
    assert abs(attached[1] - time.time_ns()) < 5e9
    assert got.values[0].type == 2 and got.values[0].integer_value > 0
    assert got.values[1].type == 0  # not set
    described, _ = client(car, "describe_parameters", "rcl_interfaces/srv/DescribeParameters").call(
        names=["max_speed"]
    )
    (max_speed,) = described.descriptors
    assert max_speed.type == 2 and not max_speed.read_only
    (limits,) = max_speed.integer_range
    assert limits.from_value <= MAX_SPEED <= limits.to_value


def set_request(car: Car, *parameters: object) -> list[object]:
    setter = client(car, "set_parameters", "rcl_interfaces/srv/SetParameters")
    response, _ = setter.call(parameters=list(parameters), timeout=15)
    return list(response.results)


def test_a_set_reaches_the_board_and_is_answered_once_read_back(car: Car) -> None:
    events = next(e for e in car.entities(16) if e.topic == "/parameter_events")
    assert events.type_name == "rcl_interfaces::msg::dds_::ParameterEvent_"
    assert events.qos == "::,1000:,:,:,,"  # rclcpp's parameter events: depth 1000
    said = peer.Received()
    subscriber = car.ros.declare_subscriber(events.data_key, said.on_sample)
    time.sleep(0.3)
    (result,) = set_request(car, peer.parameter("max_speed", MAX_SPEED))
    assert result.successful, result.reason
    time.sleep(0.3)
    subscriber.undeclare()
    (event,) = said.messages("rcl_interfaces/msg/ParameterEvent")
    (changed,) = event.changed_parameters
    assert event.node == "/appmode" and changed.name == "max_speed"
    assert changed.value.integer_value == MAX_SPEED
    got, _ = client(car, "get_parameters", "rcl_interfaces/srv/GetParameters").call(
        names=["max_speed"]
    )
    assert got.values[0].integer_value == MAX_SPEED
    frames = [f for _, f in car.frames()]
    assert "FF FE 80 80 01 00 00 03 20 00" in frames, frames[-6:]  # setting 1: 800


@pytest.mark.parametrize("car", [(False,)], indirect=True)
def test_on_the_app_port_a_set_is_its_frame(car: Car) -> None:
    (result,) = set_request(car, peer.parameter("max_speed", MAX_SPEED))
    assert result.successful, result.reason
    assert f"{{0:{MAX_SPEED}}}" in car.board_sent(), car.board_sent()[-6:]  # parameter 0


def test_refusals_say_why_and_nothing_reaches_the_board(car: Car) -> None:
    results = set_request(
        car,
        peer.parameter("max_speed", 99999),
        peer.parameter("max_speed", 2.5),
        peer.parameter("no_such", 1),
    )
    assert [r.successful for r in results] == [False, False, False]
    assert "must be in" in results[0].reason, results[0].reason
    assert "integer, not double" in results[1].reason
    assert "no parameter 'no_such'" in results[2].reason
    assert not [f for _, f in car.frames() if f.startswith("FF FE 80 80 01")], "max_speed set"
    atomic = client(car, "set_parameters_atomically", "rcl_interfaces/srv/SetParametersAtomically")
    response, _ = atomic.call(
        parameters=[peer.parameter("max_speed", 700), peer.parameter("max_speed", 600)]
    )
    assert not response.result.successful and "one parameter at a time" in response.result.reason


def test_save_sends_the_board_s_save_and_lines_go_to_rosout(car: Car) -> None:
    rosout = next(e for e in car.entities(16) if e.topic == "/rosout")
    assert rosout.type_name == "rcl_interfaces::msg::dds_::Log_"
    assert rosout.qos == ":1:,1000:,:10,0:,,"  # rcl's: transient local, 10 s lifespan
    lines = peer.Received()
    subscriber = car.ros.declare_subscriber(rosout.data_key, lines.on_sample)
    time.sleep(0.3)
    saved, _ = client(car, "save", "std_srvs/srv/Trigger").call()
    assert saved.success and "no reply" in saved.message, saved.message
    assert any(f.startswith("FF FE 80 80") for _, f in car.frames()[-3:]), car.frames()[-3:]
    time.sleep(0.5)
    subscriber.undeclare()
    logged = lines.messages("rcl_interfaces/msg/Log")
    assert any(m.msg == saved.message and m.name == "appmode" for m in logged), logged


@pytest.mark.parametrize("car", [(True, "--distro", "humble")], indirect=True)
def test_humble_s_services_answer_on_their_keys(car: Car) -> None:
    listing = services(car)["/appmode/list_parameters"]
    assert listing.type_hash == "TypeHashNotSupported"
    listed, _ = peer.ServiceClient(car.ros, listing, "rcl_interfaces/srv/ListParameters").call(
        prefixes=[], depth=0
    )
    assert "max_speed" in listed.result.names


def test_requests_rmw_zenoh_would_drop_get_no_answer_and_the_node_goes_on(car: Car) -> None:
    listing = services(car)["/appmode/list_parameters"]
    for payload, attachment in (
        (b"\x00\x01\x00\x00\x00\x00\x00\x00", None),  # no attachment
        (b"junk", peer.ATTACHED),  # no request
        (bytes(100_000), peer.ATTACHED),  # larger than any request
    ):
        replies = car.ros.get(listing.data_key, payload=payload, attachment=attachment, timeout=1)
        assert not [r for r in replies if r.ok is not None]
    listed, _ = peer.ServiceClient(car.ros, listing, "rcl_interfaces/srv/ListParameters").call(
        prefixes=["max_speed", "max"], depth=0
    )
    assert list(listed.result.names) == ["max_speed"]  # a prefix is dot-separated, as rclcpp
