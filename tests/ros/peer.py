"""A ROS 2 side on rmw_zenoh's wire, written from rmw_zenoh's docs/design.md alone (not
from appmode's code), for the tests: it finds the graph's liveliness tokens, reads a
topic's samples with their attachments, and publishes a Twist as a ROS publisher does.
zenoh and rosbags are its only tools."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import zenoh
import zenoh.ext
from rosbags.typesys import Stores, get_typestore

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
