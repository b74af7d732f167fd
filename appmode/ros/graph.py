"""A node's place in the ROS 2 graph as rmw_zenoh writes it, with no I/O
(ros2/rmw_zenoh, docs/design.md, "Topic and Service name mapping" and "Graph Cache";
rmw_zenoh_cpp/src/detail/liveliness_utils.cpp): a topic's key expression
`<domain>/<name>/<type>/<hash>`, and the liveliness tokens of a node (`NN`), its
publishers (`MP`) and its subscriptions (`MS`) under the hermetic `@ros2_lv`, with `/`
in names written `%` and the QoS in its compact form. Humble's rmw_zenoh has no type
hashes: `TypeHashNotSupported` stands in."""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

ADMIN_SPACE = "@ros2_lv"
NO_HASH = "TypeHashNotSupported"
"""What Humble's rmw_zenoh writes for a type hash (its ROS has none)."""
DISTROS = ("jazzy", "humble")
NAME_CHARS = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_")


class Reliability(IntEnum):
    """rmw_qos_reliability_policy_e."""

    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2


class Durability(IntEnum):
    """rmw_qos_durability_policy_e."""

    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2


class History(IntEnum):
    """rmw_qos_history_policy_e."""

    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2


@dataclass(frozen=True, slots=True)
class Qos:
    """The QoS an entity declares (deadline, lifespan and liveliness: rmw_zenoh's
    defaults, infinite and automatic)."""

    depth: int = 10
    reliability: Reliability = Reliability.RELIABLE
    durability: Durability = Durability.VOLATILE
    history: History = History.KEEP_LAST
    lifespan: tuple[int, int] | None = None
    """Seconds and nanoseconds a sample lives (None: for ever, rmw_zenoh's default)."""

    def text(self) -> str:
        """The QoS as a token writes it: `reliability:durability:history,depth:` then
        deadline, lifespan and liveliness, each field empty where it is rmw_zenoh's
        default (RELIABLE, VOLATILE, KEEP_LAST, depth 42, infinite, automatic):
        `::,10:,:,:,,` for depth 10. Humble's rmw_zenoh (0.1.x) and Jazzy's (0.2.x) write
        it alike (`qos_to_keyexpr` in liveliness_utils.cpp of each), and rebuild the
        token from the fields they parse before hashing it into the GID."""

        def kind(value: IntEnum, default: IntEnum) -> str:
            return "" if value == default else str(int(value))

        depth = "" if self.depth == DEFAULT_DEPTH else str(self.depth)
        lifespan = "," if self.lifespan is None else "{},{}".format(*self.lifespan)
        return (
            f"{kind(self.reliability, Reliability.RELIABLE)}:"
            f"{kind(self.durability, Durability.VOLATILE)}:"
            f"{kind(self.history, History.KEEP_LAST)},{depth}:,:{lifespan}:,,"
        )


DEFAULT_DEPTH = 42
"""rmw_zenoh's depth for a KEEP_LAST QoS of depth 0."""


def mangle(name: str) -> str:
    """A name as a key expression's chunk: `/` written `%`."""
    return name.replace("/", "%")


def dds_type(ros_type: str) -> str:
    """`geometry_msgs/msg/Twist` as CDR names it: `geometry_msgs::msg::dds_::Twist_`."""
    package, kind, name = ros_type.split("/")
    return f"{package}::{kind}::dds_::{name}_"


class BadName(ValueError):
    """A namespace or node name ROS would not take, and why."""


def namespace(text: str) -> str:
    """A namespace as ROS writes it: `/` alone, or `/robot1` (`robot1` and `/robot1/`
    alike); BadName if a part is not letters, digits and `_` starting with no digit."""
    parts = [part for part in text.strip().split("/") if part]
    for part in parts:
        if not (set(part) <= NAME_CHARS and not part[0].isdigit()):
            raise BadName(
                f"namespace {text!r}: each part is letters, digits and _, not starting with "
                "a digit (such as /robot1)"
            )
    return "/" + "/".join(parts)


def node_name(text: str) -> str:
    if not (text and set(text) <= NAME_CHARS and not text[0].isdigit()):
        raise BadName(f"node name {text!r}: letters, digits and _, not starting with a digit")
    return text


@dataclass(frozen=True, slots=True)
class Node:
    """A node: its domain, namespace and name, the Zenoh session it lives in, and which
    ROS it speaks to (`jazzy` and later, or `humble`)."""

    domain: int
    namespace: str
    name: str
    zid: str
    distro: str = "jazzy"
    node_id: int = 0

    def resolve(self, topic: str) -> str:
        """A topic's fully qualified name: `/tf` as it is, `cmd_vel` in the namespace,
        `~/raw` under the node."""
        if topic.startswith("/"):
            return topic
        base = self.namespace.rstrip("/")
        if topic.startswith("~/"):
            return f"{base}/{self.name}/{topic[2:]}"
        return f"{base}/{topic}"

    def topic_key(self, topic: str, ros_type: str, type_hash: str) -> str:
        """Where a topic's samples go: `<domain>/<name>/<type>/<hash>`."""
        name = self.resolve(topic).strip("/")
        return f"{self.domain}/{name}/{dds_type(ros_type)}/{self._hash(type_hash)}"

    def _hash(self, type_hash: str) -> str:
        return NO_HASH if self.distro == "humble" else type_hash

    def _prefix(self, entity_id: int, kind: str) -> str:
        return "/".join(
            (
                ADMIN_SPACE,
                str(self.domain),
                self.zid,
                str(self.node_id),
                str(entity_id),
                kind,
                "%",  # no SROS enclave: `/`
                mangle(self.namespace),
                self.name,
            )
        )

    def node_token(self) -> str:
        """The node's liveliness token (`NN`; its entity id is its node id)."""
        return self._prefix(self.node_id, "NN")

    def entity_token(
        self, entity_id: int, kind: str, topic: str, ros_type: str, type_hash: str, qos: Qos
    ) -> str:
        """A publisher's (`MP`) or a subscription's (`MS`) liveliness token."""
        return "/".join(
            (
                self._prefix(entity_id, kind),
                mangle(self.resolve(topic)),
                dds_type(ros_type),
                self._hash(type_hash),
                qos.text(),
            )
        )
