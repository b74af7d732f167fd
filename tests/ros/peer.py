"""A ROS 2 side on rmw_zenoh's wire, written from rmw_zenoh's docs/design.md alone (not
from appmode's code), for the tests: it finds the graph's liveliness tokens, reads a
topic's samples with their attachments, publishes a Twist as a ROS publisher does, and
calls a service as a ROS client does (rmw_client_data.cpp).
zenoh and rosbags are its only tools."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import zenoh
import zenoh.ext
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

JAZZY = get_typestore(Stores.ROS2_JAZZY)


def router(endpoint: str) -> zenoh.Session:
    """A Zenoh router with no authentication, as `ros2 run rmw_zenoh_cpp rmw_zenohd`."""
    config = zenoh.Config()
    config.insert_json5("mode", '"router"')
    config.insert_json5("listen/endpoints", f'["{endpoint}"]')
    config.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(config)


def session(endpoint: str) -> zenoh.Session:
    """A ROS context's session: a peer connected to the router (the design doc's
    defaults), multicast off."""
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("connect/endpoints", f'["{endpoint}"]')
    config.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    config.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(config)


@dataclass(frozen=True)
class Entity:
    """A liveliness token, read as the design doc lays it out."""

    domain: int
    zid: str
    kind: str
    namespace: str
    node: str
    topic: str = ""
    type_name: str = ""
    type_hash: str = ""
    qos: str = ""

    @classmethod
    def parse(cls, key: str) -> Entity:
        parts = key.split("/")
        assert parts[0] == "@ros2_lv", key
        domain, zid, kind = int(parts[1]), parts[2], parts[5]
        namespace, node = parts[7].replace("%", "/"), parts[8]
        if kind == "NN":
            return cls(domain, zid, kind, namespace, node)
        topic, type_name, type_hash, qos = parts[9].replace("%", "/"), *parts[10:13]
        return cls(domain, zid, kind, namespace, node, topic, type_name, type_hash, qos)

    @property
    def data_key(self) -> str:
        """Where its samples go: `<domain>/<topic, no leading slash>/<type>/<hash>`."""
        return f"{self.domain}/{self.topic.strip('/')}/{self.type_name}/{self.type_hash}"


def graph(ros: zenoh.Session, domain: int = 0) -> list[Entity]:
    replies = ros.liveliness().get(f"@ros2_lv/{domain}/**", timeout=2)
    return [Entity.parse(str(r.ok.key_expr)) for r in replies if r.ok is not None]


@dataclass
class Received:
    """A topic's samples: each payload, and its attachment's three fields."""

    payloads: list[bytes] = field(default_factory=list)
    attachments: list[tuple[int, int, bytes]] = field(default_factory=list)

    def on_sample(self, sample: zenoh.Sample) -> None:
        assert sample.attachment is not None, "rmw_zenoh puts an attachment on every sample"
        sequence, stamp, gid = zenoh.ext.z_deserialize(
            tuple[zenoh.ext.Int64, zenoh.ext.Int64, bytes], sample.attachment
        )
        self.attachments.append((int(sequence), int(stamp), bytes(gid)))
        self.payloads.append(sample.payload.to_bytes())

    def messages(self, ros_type: str) -> list[Any]:
        return [JAZZY.deserialize_cdr(p, ros_type) for p in self.payloads]


class TwistPublisher:
    """A ROS publisher of geometry_msgs/Twist on `entity`'s topic (the subscription's
    token tells where): a sample with the attachment the design doc describes."""

    GID = bytes(range(16))

    def __init__(self, ros: zenoh.Session, entity: Entity) -> None:
        self.publisher = ros.declare_publisher(entity.data_key)
        self.sequence = 0

    def publish(self, forward: float, turn: float = 0.0) -> None:
        self.sequence += 1
        attachment = zenoh.ext.z_serialize(
            (zenoh.ext.Int64(self.sequence), zenoh.ext.Int64(time.time_ns()), self.GID)
        )
        self.publisher.put(twist_payload(forward, turn), attachment=attachment)


ATTACHED = zenoh.ext.z_serialize((zenoh.ext.Int64(1), zenoh.ext.Int64(0), bytes(range(16))))
"""An attachment of rmw_zenoh's form, for a sample that is otherwise no ROS message."""


def twist_payload(forward: float, turn: float = 0.0) -> bytes:
    """A geometry_msgs/Twist as CDR (Jazzy's)."""
    types = JAZZY.types
    vector = types["geometry_msgs/msg/Vector3"]
    twist = types["geometry_msgs/msg/Twist"](
        linear=vector(x=forward, y=0.0, z=0.0), angular=vector(x=0.0, y=0.0, z=turn)
    )
    return bytes(JAZZY.serialize_cdr(twist, "geometry_msgs/msg/Twist"))


SERVICES = {
    # rcl_interfaces/srv/*.srv and std_srvs/srv/Trigger.srv: request, then response
    "rcl_interfaces/srv/ListParameters": (
        "uint64 DEPTH_RECURSIVE=0\nstring[] prefixes\nuint64 depth",
        "rcl_interfaces/ListParametersResult result",
    ),
    "rcl_interfaces/srv/GetParameters": (
        "string[] names",
        "rcl_interfaces/ParameterValue[] values",
    ),
    "rcl_interfaces/srv/GetParameterTypes": ("string[] names", "uint8[] types"),
    "rcl_interfaces/srv/DescribeParameters": (
        "string[] names",
        "rcl_interfaces/ParameterDescriptor[] descriptors",
    ),
    "rcl_interfaces/srv/SetParameters": (
        "rcl_interfaces/Parameter[] parameters",
        "rcl_interfaces/SetParametersResult[] results",
    ),
    "rcl_interfaces/srv/SetParametersAtomically": (
        "rcl_interfaces/Parameter[] parameters",
        "rcl_interfaces/SetParametersResult result",
    ),
    "std_srvs/srv/Trigger": ("", "bool success\nstring message"),
}
for _service, _parts in SERVICES.items():
    for _suffix, _text in zip(("_Request", "_Response"), _parts, strict=True):
        JAZZY.register(get_types_from_msg(_text, f"{_service}{_suffix}"))


def srv_type(service: str, suffix: str) -> str:
    """Where rosbags keeps a service's request or response (`pkg/srv/msg/Name_Request`)."""
    package, _, name = service.split("/")
    return f"{package}/srv/msg/{name}_{suffix}"


class ServiceClient:
    """A ROS 2 client as rmw_client_data.cpp sends a request: a get on the server's key
    (its `SS` token tells where) with target ALL_COMPLETE, no consolidation, the
    request's CDR as payload and the client's attachment (sequence number, time, GID)."""

    GID = bytes(range(100, 116))

    def __init__(self, ros: zenoh.Session, entity: Entity, service: str) -> None:
        self.ros, self.entity, self.service = ros, entity, service
        self.sequence = 0

    def call(self, timeout: float = 10.0, **fields: Any) -> tuple[Any, tuple[int, int, bytes]]:
        """The response, and its attachment's three fields."""
        request = JAZZY.types[srv_type(self.service, "Request")](**fields)
        payload = bytes(JAZZY.serialize_cdr(request, srv_type(self.service, "Request")))
        self.sequence += 1
        attachment = zenoh.ext.z_serialize(
            (zenoh.ext.Int64(self.sequence), zenoh.ext.Int64(time.time_ns()), self.GID)
        )
        replies = self.ros.get(
            self.entity.data_key,
            target=zenoh.QueryTarget.ALL_COMPLETE,
            consolidation=zenoh.ConsolidationMode.NONE,
            payload=payload,
            attachment=attachment,
            timeout=timeout,
        )
        for reply in replies:
            assert reply.ok is not None, f"an error reply: {reply.err}"
            sample = reply.ok
            assert sample.attachment is not None, "rmw_zenoh's server attaches every reply"
            sequence, stamp, gid = zenoh.ext.z_deserialize(
                tuple[zenoh.ext.Int64, zenoh.ext.Int64, bytes], sample.attachment
            )
            response_type = srv_type(self.service, "Response")
            response = JAZZY.deserialize_cdr(sample.payload.to_bytes(), response_type)
            return response, (int(sequence), int(stamp), bytes(gid))
        raise AssertionError(f"no reply from {self.entity.data_key} in {timeout} s")


def parameter(name: str, value: int | float) -> Any:
    """An rcl_interfaces/Parameter as `ros2 param set` sends it (integer or double)."""
    types = JAZZY.types
    kind = 2 if isinstance(value, int) else 3
    parameter_value = types["rcl_interfaces/msg/ParameterValue"](
        type=kind,
        bool_value=False,
        integer_value=value if kind == 2 else 0,
        double_value=float(value) if kind == 3 else 0.0,
        string_value="",
        byte_array_value=np.zeros(0, dtype=np.uint8),
        bool_array_value=np.zeros(0, dtype=bool),
        integer_array_value=np.zeros(0, dtype=np.int64),
        double_array_value=np.zeros(0, dtype=np.float64),
        string_array_value=[],
    )
    return types["rcl_interfaces/msg/Parameter"](name=name, value=parameter_value)
