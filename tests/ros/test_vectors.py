"""rmw_zenoh's wire format, pinned: the examples of its docs/design.md (topic keys and
liveliness tokens), the attachment's layout (zenoh-ext's own serializer as the
reference), XXH3-128's published vector, and the RIHS01 hash of every type the node
uses — as rosbags computes them, each checked against the hash other implementations
publish for it (rclpy's `ros2 topic info -v`, ros-z, rmw_zenoh's own example)."""

from __future__ import annotations

import struct

import pytest

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")
zenoh_ext = pytest.importorskip("zenoh.ext", reason="the ros extra (eclipse-zenoh) is missing")

from appmode.ros import interfaces, messages  # noqa: E402
from appmode.ros.graph import Durability, Node, Qos, Reliability, namespace  # noqa: E402
from appmode.ros.wire import attachment, gid, read_attachment  # noqa: E402

STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
HASHES = {
    messages.STRING: STRING_HASH,
    messages.TWIST: "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a",
    messages.TWIST_STAMPED: (
        "RIHS01_5f0fcd4f81d5d06ad9b4c4c63e3ea51b82d6ae4d0558f1d475229b1121db6f64"
    ),
    messages.ODOMETRY: "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0",
    messages.BATTERY: "RIHS01_4bee5dfce981c98faa6828b868307a0a73f992ed0789f374ee96c8f840e69741",
    messages.IMU: "RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b",
    messages.TF: "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    # PowerVoltage (--topics wheeltec): ROS 2's own golden value (rosidl's CHECK_GOLDEN_HASH)
    messages.FLOAT32: "RIHS01_7170d3d8f841f7be3172ce5f4f59f3a4d7f63b0447e8b33327601ad64d83d6e2",
    # /rosout (as a `ros2` CLI node's token on rmw_zenoh shows it)
    messages.LOG: "RIHS01_e28ce254ca8abc06abf92773b74602cdbf116ed34fbaf294fb9f81da9f318eac",
    messages.PARAMETER_EVENT: (
        "RIHS01_043e627780fcad87a22d225bc2a037361dba713fca6a6b9f4b869a5aa0393204"
    ),
}
SERVICE_HASHES = {
    # rmw_zenoh's docs/design.md, "Services": its example service
    "example_interfaces/srv/AddTwoInts": (
        "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
    ),
    # as `ros2 service info -v` prints them for any rclcpp node on Jazzy
    "rcl_interfaces/srv/ListParameters": (
        "RIHS01_3e6062bfbb27bfb8730d4cef2558221f51a11646d78e7bb30a1e83afac3aad9d"
    ),
    "rcl_interfaces/srv/GetParameters": (
        "RIHS01_bf9803d5c74cf989a5de3e0c2e99444599a627c7ff75f97b8c05b01003675cbc"
    ),
    "rcl_interfaces/srv/GetParameterTypes": (
        "RIHS01_da199c878688b3e530bdfe3ca8f74cb9fa0c303101e980a9e8f260e25e1c80ca"
    ),
    "rcl_interfaces/srv/DescribeParameters": (
        "RIHS01_845b484d71eb0673dae682f2e3ba3c4851a65a3dcfb97bddd82c5b57e91e4cff"
    ),
    "rcl_interfaces/srv/SetParameters": (
        "RIHS01_56eed9a67e169f9cb6c1f987bc88f868c14a8fc9f743a263bc734c154015d7e0"
    ),
    "rcl_interfaces/srv/SetParametersAtomically": (
        "RIHS01_0e192ef259c07fc3c07a13191d27002222e65e00ccec653ca05e856f79285fcd"
    ),
    "std_srvs/srv/Trigger": (
        "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"
    ),
}


def test_the_type_hashes_of_every_type_used() -> None:
    jazzy = messages.Messages("jazzy")
    assert set(HASHES) == set(messages.TYPES)
    for ros_type, expected in HASHES.items():
        assert jazzy.type_hash(ros_type) == expected, ros_type


def test_the_type_hashes_of_every_service_served(monkeypatch: pytest.MonkeyPatch) -> None:
    """A service's hash: its request, response and event as REP-2016 describes them
    (rmw_zenoh's example among them, its two fields each way given here)."""
    example = {"example_interfaces/srv/AddTwoInts": ("int64 a\nint64 b", "int64 sum")}
    monkeypatch.setattr(interfaces, "SERVICES", {**interfaces.SERVICES, **example})
    jazzy = messages.Messages("jazzy")
    assert set(SERVICE_HASHES) == set(interfaces.SERVICES)
    for service, expected in SERVICE_HASHES.items():
        assert interfaces.service_hash(service, jazzy.store) == expected, service


def test_the_design_doc_s_topic_keys() -> None:
    plain = Node(0, "/", "talker", "z")
    assert plain.topic_key("chatter", messages.STRING, STRING_HASH) == (
        f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    )
    robot = Node(0, namespace("robot1"), "talker", "z")
    assert robot.topic_key("chatter", messages.STRING, STRING_HASH) == (
        f"0/robot1/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    )
    assert robot.resolve("/tf") == "/tf" and robot.resolve("~/raw") == "/robot1/talker/raw"


def test_the_design_doc_s_liveliness_tokens() -> None:
    listener = Node(2, "/", "listener", "aac3178e146ba6f1fc6e6a4085e77f21")
    assert (
        listener.node_token() == "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"
    )
    subscription = listener.entity_token(
        10, "MS", "chatter", messages.STRING, STRING_HASH, Qos(depth=10)
    )
    assert subscription == (
        "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/"
        f"std_msgs::msg::dds_::String_/{STRING_HASH}/::,10:,:,:,,"
    )
    talker = Node(2, "/", "talker", "8b20917502ee955ac4476e0266340d5c")
    publisher = talker.entity_token(10, "MP", "chatter", messages.STRING, STRING_HASH, Qos(depth=7))
    assert publisher == (
        "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/"
        f"std_msgs::msg::dds_::String_/{STRING_HASH}/::,7:,:,:,,"
    )


def test_humble_writes_no_hash_and_its_qos_as_jazzy_does() -> None:
    """Issue 77.1: Humble's tokens wrote the QoS kinds out (`1:2:1,10:,:,:,,`) from a
    stale comment; rmw_zenoh 0.1.9's qos_to_keyexpr (liveliness_utils.cpp), as 0.2.10's,
    leaves each field empty where it is the default (RELIABLE 1, VOLATILE 2, KEEP_LAST 1,
    depth 42, infinite, automatic)."""
    node = Node(0, "/", "appmode", "z", distro="humble")
    assert node.topic_key("odom", messages.ODOMETRY, "RIHS01_x").endswith(
        "/nav_msgs::msg::dds_::Odometry_/TypeHashNotSupported"
    )
    token = node.entity_token(1, "MP", "odom", messages.ODOMETRY, "RIHS01_x", Qos(depth=10))
    assert token.endswith("/nav_msgs::msg::dds_::Odometry_/TypeHashNotSupported/::,10:,:,:,,")
    assert Qos(depth=42).text() == "::,:,:,:,,"
    transient = Qos(depth=1, durability=Durability.TRANSIENT_LOCAL)
    assert transient.text() == ":1:,1:,:,:,,"
    assert Qos(depth=5, reliability=Reliability.BEST_EFFORT).text() == "2::,5:,:,:,,"


def test_the_attachment_is_zenoh_ext_s_serialization_of_its_three_fields() -> None:
    wire = attachment(7, 1_700_000_000_123_456_789, bytes(range(16)))
    reference = zenoh_ext.z_serialize(
        (zenoh_ext.Int64(7), zenoh_ext.Int64(1_700_000_000_123_456_789), bytes(range(16)))
    )
    assert wire == reference.to_bytes() and len(wire) == 33
    assert read_attachment(wire) == (7, 1_700_000_000_123_456_789, bytes(range(16)))


def test_a_gid_is_xxh3_128_of_the_token_low_half_first() -> None:
    empty = int("99aa06d3014798d86001c324468d497f", 16)  # XXH3_128(""), the published vector
    assert gid("") == struct.pack("<QQ", empty & (2**64 - 1), empty >> 64)
    assert len(gid("@ros2_lv/0/z/0/0/NN/%/%/appmode")) == 16
