"""`appmode ros` seen from a ROS 2 side written from rmw_zenoh's design doc (tests/ros/
peer.py), through a Zenoh router on loopback: the node's tokens, odometry with valid
attachments, cmd_vel driving the car — judged on the board's own recording — and
silence and SIGTERM stopping it."""

from __future__ import annotations

import signal
import time

import pytest

pytest.importorskip("zenoh", reason="the ros extra (eclipse-zenoh) is not installed")
pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")

from tests.ros import peer
from tests.ros.conftest import Car
from tests.support.processes import stop_process

ODOMETRY_JAZZY = "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"
TWIST_JAZZY = "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"
ZERO = "FF FE 01 00 00 00 00 00 00 00"


def test_the_node_s_tokens_odometry_and_cmd_vel_as_a_ros_side_sees_them(car: Car) -> None:
    entities = {(e.kind, e.topic or e.node): e for e in car.entities(7)}
    assert ("NN", "appmode") in entities
    odom = entities[("MP", "/odom")]
    assert odom.type_name == "nav_msgs::msg::dds_::Odometry_" and odom.type_hash == ODOMETRY_JAZZY
    assert odom.qos == "::,10:,:,:,,"
    assert entities[("MP", "/battery_state")].type_name == "sensor_msgs::msg::dds_::BatteryState_"
    cmd_vel = entities[("MS", "/cmd_vel")]
    assert cmd_vel.type_name == "geometry_msgs::msg::dds_::Twist_"
    assert cmd_vel.type_hash == TWIST_JAZZY
    assert len({e.zid for e in entities.values()}) == 1

    odometry = peer.Received()
    subscriber = car.ros.declare_subscriber(odom.data_key, odometry.on_sample)
    time.sleep(1.0)
    assert len(odometry.payloads) >= 5
    sequences = [a[0] for a in odometry.attachments]
    assert sequences == sorted(sequences) and len(set(sequences)) == len(sequences)
    assert all(abs(a[1] - time.time_ns()) < 5e9 and len(a[2]) == 16 for a in odometry.attachments)
    assert len({a[2] for a in odometry.attachments}) == 1  # one publisher, one GID
    first = odometry.messages("nav_msgs/msg/Odometry")[-1]
    assert first.header.frame_id == "odom" and first.child_frame_id == "base_link"

    twist = peer.TwistPublisher(car.ros, cmd_vel)
    start = time.monotonic()
    while time.monotonic() - start < 2.0:
        twist.publish(0.3)
        time.sleep(0.05)
    forward = [f for _, f in car.frames() if f.startswith("FF FE 01 00 00 01 2C")]
    assert forward, f"no velocity frame y=300 (0.3 m/s) on the board: {car.frames()[-4:]}"
    moving = odometry.messages("nav_msgs/msg/Odometry")[-1]
    assert 0.2 < moving.twist.twist.linear.x < 0.35, moving.twist.twist
    assert moving.pose.pose.position.x > 0.05
    silent = time.monotonic()
    board_silent = car.board.clock_after  # the board's clock of this moment
    end = silent + 5
    while time.monotonic() < end and car.frames()[-1][1] != ZERO:
        time.sleep(0.02)
    stopped_at, last = car.frames()[-1]
    assert last == ZERO, car.frames()[-3:]
    assert stopped_at + board_silent - silent < 0.8, "the stop came later than 0.8 s"
    subscriber.undeclare()

    node = car.node
    node.send_signal(signal.SIGTERM)  # type: ignore[attr-defined]
    node.communicate(timeout=15)  # type: ignore[attr-defined]
    assert node.returncode == 0  # type: ignore[attr-defined]
    time.sleep(0.5)
    assert peer.graph(car.ros) == [], "the tokens stay after the node ended"
    assert car.frames()[-1][1] == ZERO


@pytest.mark.parametrize("car", [(True, "--distro", "humble")], indirect=True)
def test_humble_writes_no_type_hash(car: Car) -> None:
    entities = car.entities(7)
    assert all(e.type_hash == "TypeHashNotSupported" for e in entities if e.kind != "NN")
    odom = next(e for e in entities if e.topic == "/odom")
    assert odom.qos == "::,10:,:,:,,"  # as Humble's rmw_zenoh writes it (issue 77.1)
    odometry = peer.Received()
    car.ros.declare_subscriber(odom.data_key, odometry.on_sample)
    time.sleep(1.0)
    assert odometry.payloads, "nothing on 0/odom/…/TypeHashNotSupported"


@pytest.mark.parametrize("car", [(False,)], indirect=True)
def test_on_the_app_port_cmd_vel_is_the_nearest_direction_and_silence_stops(car: Car) -> None:
    cmd_vel = next(e for e in car.entities(7) if e.topic == "/cmd_vel")
    twist = peer.TwistPublisher(car.ros, cmd_vel)
    junk = car.ros.declare_publisher(cmd_vel.data_key)
    junk.put(b"\x00\x01\x00\x00not a twist", attachment=peer.ATTACHED)  # ignored, said once
    end = time.monotonic() + 3
    while time.monotonic() < end and "A" not in car.board_sent():
        twist.publish(0.2)
        time.sleep(0.05)
    for _ in range(20):
        twist.publish(0.2)
        time.sleep(0.05)
    sent = car.board_sent()
    assert "J" in sent and "A" in sent, sent[-8:]
    assert "{0:200}" in sent, "the speed asked (0.2 m/s = 200 mm/s) as max_speed"
    silent = time.monotonic()
    end = silent + 5
    while time.monotonic() < end and car.board_sent()[-1] != "Z":
        time.sleep(0.02)
    stopped = car.board.clock_after + car.board_timed()[-1][0]
    assert car.board_sent()[-1] == "Z" and stopped - silent < 0.8
    err = stop_process(car.node)  # type: ignore[arg-type]
    assert "a cmd_vel that is no Twist was ignored" in err and "Traceback" not in err


def _odometry_while(car: Car, cmd_vel: peer.Entity, forward: float, turn: float) -> list[float]:
    """Publish cmd_vel (forward m/s, turn rad/s) at 20 Hz for 3 s: the mean twist of the
    odom messages of its last 1.5 s, as (forward, left, turn)."""
    odom = next(e for e in car.entities(7) if e.topic == "/odom")
    odometry = peer.Received()
    subscriber = car.ros.declare_subscriber(odom.data_key, odometry.on_sample)
    twist = peer.TwistPublisher(car.ros, cmd_vel)
    start = time.monotonic()
    settled = 0
    while time.monotonic() - start < 3.0:
        twist.publish(forward, turn)
        if time.monotonic() - start < 1.5:
            settled = len(odometry.payloads)
        time.sleep(0.05)
    subscriber.undeclare()
    kept = odometry.messages("nav_msgs/msg/Odometry")[settled:]
    assert len(kept) >= 5, f"{len(kept)} odom messages in 1.5 s"
    twists = [m.twist.twist for m in kept]
    return [
        sum(t.linear.x for t in twists) / len(twists),
        sum(t.linear.y for t in twists) / len(twists),
        sum(t.angular.z for t in twists) / len(twists),
    ]


@pytest.mark.slow
@pytest.mark.parametrize(
    "car",
    [(False,), (True,), (True, "--profile", "minibalance")],
    ids=["sheet-app-port", "sheet-control-port", "minibalance-control-port"],
    indirect=True,
)
def test_cmd_vel_gives_the_odometry_it_asked_for_on_every_port(car: Car) -> None:
    cmd_vel = next(e for e in car.entities(7) if e.topic == "/cmd_vel")
    forward, left, turn = _odometry_while(car, cmd_vel, 0.3, 0.0)
    assert forward == pytest.approx(0.3, abs=0.09) and abs(left) < 0.05 and abs(turn) < 0.1
    forward, left, turn = _odometry_while(car, cmd_vel, 0.0, 0.5)
    assert turn == pytest.approx(0.5, abs=0.2) and abs(forward) < 0.05 and abs(left) < 0.05
    silent = time.monotonic()
    end = silent + 5
    while time.monotonic() < end and not _stopped(car):
        time.sleep(0.02)
    assert _stopped(car), "the car was not stopped after cmd_vel went silent"
    err = stop_process(car.node)  # type: ignore[arg-type]
    assert "Traceback" not in err and "not sent" not in err, err


def _stopped(car: Car) -> bool:
    """The last thing the board took stops it: Z on the APP port, or the zero frame."""
    last = max([*car.board_timed(), *car.frames()], default=(0.0, ""), key=lambda u: u[0])[1]
    return last in ("Z", ZERO)


@pytest.mark.parametrize(
    "car", [(False,), (True,)], ids=["app-port", "control-port"], indirect=True
)
def test_out_of_range_cmd_vel_is_refused_or_clamped_and_the_node_keeps_running(car: Car) -> None:
    """Issue 80.10: linear.x = 1e307 ended the node (OverflowError), 70 m/s on the APP
    port exited 2. A twist past 100 m/s is no car's: refused, said once; 70 m/s is
    driven at what the port can; the node runs on and drives the next cmd_vel."""
    cmd_vel = next(e for e in car.entities(7) if e.topic == "/cmd_vel")
    twist = peer.TwistPublisher(car.ros, cmd_vel)
    for forward in (1e307, -1e307, 70.0, 70.0):
        twist.publish(forward)
        time.sleep(0.1)
    end = time.monotonic() + 1.5
    while time.monotonic() < end:
        twist.publish(0.2)
        time.sleep(0.05)
    assert car.node.poll() is None, "the node ended"  # type: ignore[attr-defined]
    err = stop_process(car.node)  # type: ignore[arg-type]
    assert "no car's" in err and "Traceback" not in err and "internal error" not in err, err
    if car.frames():
        frames = [f for _, f in car.frames()]
        assert "FF FE 01 00 00 00 C8 00 00 00" in frames, frames[-5:]  # y = 200: 0.2 m/s
    else:
        assert "{0:200}" in car.board_sent(), car.board_sent()[-8:]


@pytest.mark.slow
def test_imu_and_battery_carry_data_consistent_with_odom(car: Car) -> None:
    """Issue 77.3: imu carried an orientation only, battery_state a percentage with its
    voltage NaN. Turning at 0.5 rad/s, imu's angular velocity agrees with odom's turn
    (the simulated gyro turns at the profile's velocity unit), and the battery has a
    voltage."""
    entities = car.entities(7)
    cmd_vel = next(e for e in entities if e.topic == "/cmd_vel")
    imu, battery = peer.Received(), peer.Received()
    subscribers = [
        car.ros.declare_subscriber(next(e for e in entities if e.topic == topic).data_key, got)
        for topic, got in (("/imu", imu.on_sample), ("/battery_state", battery.on_sample))
    ]
    turn = _odometry_while(car, cmd_vel, 0.0, 0.5)[2]
    for subscriber in subscribers:
        subscriber.undeclare()
    rates = [m.angular_velocity.z for m in imu.messages("sensor_msgs/msg/Imu")[-5:]]
    assert all(rate == pytest.approx(turn, abs=0.2) for rate in rates), (rates, turn)
    last = imu.messages("sensor_msgs/msg/Imu")[-1]
    assert last.angular_velocity_covariance[0] > 0, "a rate with its variance"
    volts = [m.voltage for m in battery.messages("sensor_msgs/msg/BatteryState")]
    assert volts and all(11.0 <= v <= 12.7 for v in volts), volts[-3:]


def test_a_cmd_vel_without_rmw_zenohs_attachment_is_dropped_as_rmw_zenoh_drops_it(
    car: Car,
) -> None:
    """Issue 77: a sample with no attachment, or a 10-byte one, drove the car; rmw_zenoh's
    subscription drops the first (rmw_subscription_data.cpp) and cannot read the second."""
    cmd_vel = next(e for e in car.entities(7) if e.topic == "/cmd_vel")
    twist = peer.TwistPublisher(car.ros, cmd_vel)
    payload = peer.twist_payload(0.3)
    end = time.monotonic() + 1.5
    while time.monotonic() < end:
        twist.publisher.put(payload)  # no attachment
        twist.publisher.put(payload, attachment=bytes(10))
        time.sleep(0.05)
    moved = [f for _, f in car.frames() if f.startswith("FF FE 01") and f != ZERO]
    assert "A" not in car.board_sent() and not moved, "driven by samples rmw_zenoh drops"
    twist.publish(0.3)  # with rmw_zenoh's attachment: taken
    err = stop_process(car.node)  # type: ignore[arg-type]
    assert "was dropped, as rmw_zenoh drops it" in err, err
