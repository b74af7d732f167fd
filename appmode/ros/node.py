"""The car as a ROS 2 node on rmw_zenoh's wire: a driving session (the same stop
authority as every view: a `cmd_vel` is a held key whose repeats keep it alive) and a
Zenoh session that ROS sees as a node — its liveliness tokens, `cmd_vel` taken, `odom`,
`tf`, `battery_state`, `imu` and `~/raw` published from the board's records.

`cmd_vel` samples arrive on Zenoh's threads and wait in a short queue; the session is
driven from the node's own loop, as a view drives it, so nothing of Zenoh's can hold up
the car's stop."""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from appmode.protocol.odometry import Odometry, Pose2D
from appmode.protocol.render import to_json
from appmode.protocol.sensed import YAW_WINDOW, Inertial, yaw_rate
from appmode.protocol.twist import BadTwist, Twist
from appmode.ros import rosout
from appmode.ros.graph import Durability, Node, Qos
from appmode.ros.messages import (
    BATTERY,
    FLOAT32,
    IMU,
    LOG,
    ODOMETRY,
    PARAMETER_EVENT,
    STRING,
    TF,
    TWIST,
    TWIST_STAMPED,
    Messages,
    volts_of,
)
from appmode.ros.parameters import SERVICES, Parameters
from appmode.ros.services import Request, Services
from appmode.ros.wire import BadAttachment, attachment, gid, read_attachment

if TYPE_CHECKING:
    import zenoh

    from appmode.host.app.state import HostState
    from appmode.session.base import BaseSession

TICK = 0.01
"""Seconds between two turns of the node's loop (the session's reads, the queue)."""
QUEUE = 8
"""cmd_vel samples kept waiting at most (the newest count: a twist replaces the last)."""
STATIC = Qos(depth=1, durability=Durability.TRANSIENT_LOCAL)
"""tf_static's QoS, as robot_state_publisher's: reliable, transient local, depth 1."""
HEARTBEAT = 0.5
"""Seconds between a transient-local publisher's sample-miss heartbeats (rmw_zenoh's
SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD, sporadic)."""
STILL = Pose2D(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
"""No offset: base_footprint lies under base_link (a flat car's ground projection)."""
BATTERY_EVERY = 10
"""IMU readings a battery_state is sent for (a chassis's 20 Hz status: 2 Hz)."""
Log = Callable[[str], None]


def footprint(base: str) -> str:
    """The ground projection of the car's frame `base` (REP 120), with `base`'s prefix."""
    prefix, _, _ = base.rpartition("/")
    return f"{prefix}/base_footprint" if prefix else "base_footprint"


@dataclass(frozen=True, slots=True)
class TopicSet:
    """What the node publishes each reading as: the topic (None: not published) and, for
    the battery, its message type; the frames it names."""

    odom: str
    tf: str | None
    tf_static: str | None
    """Where the fixed frames go (base_link → base_footprint), transient local."""
    imu: str
    battery: str
    battery_type: str
    raw: str | None
    odom_frame: str
    base_frame: str
    imu_frame: str

    def placed(
        self, namespace: str, prefix: str = "", odom: str | None = None, base: str | None = None
    ) -> TopicSet:
        """This set for a node in `namespace`: its transforms on the namespace's own `tf`
        (two cars' trees apart, where a namespaced Nav2 listens), its frames `odom` and
        `base` (else the set's; the IMU's follows the base's), each after `prefix`."""
        base_frame = base or self.base_frame
        imu = base_frame if self.imu_frame == self.base_frame else self.imu_frame

        def placed(topic: str | None) -> str | None:
            return topic if topic is None or namespace == "/" else topic.lstrip("/")

        return replace(
            self,
            tf=placed(self.tf),
            tf_static=placed(self.tf_static),
            odom_frame=prefix + (odom or self.odom_frame),
            base_frame=prefix + base_frame,
            imu_frame=prefix + imu,
        )


TOPIC_SETS = {
    "appmode": TopicSet(
        "odom", "/tf", "/tf_static", "imu", "battery_state", BATTERY, "~/raw",
        "odom", "base_link", "base_link",
    ),
    # turn_on_wheeltec_robot, ROS 2: odom (odom_combined → base_footprint, no TF of its
    # own: an EKF broadcasts it), imu/data_raw in gyro_link, PowerVoltage in volts
    "wheeltec": TopicSet(
        "odom", None, None, "imu/data_raw", "PowerVoltage", FLOAT32, None,
        "odom_combined", "base_footprint", "gyro_link",
    ),
}  # fmt: skip
"""The topic sets `appmode ros --topics` names."""


@dataclass(frozen=True, slots=True)
class Options:
    """How the node is seen and what it takes: `stamped` cmd_vel (TwistStamped, as
    Jazzy's Nav2 sends it), the silence after which it stops, the topics and frames it
    publishes (`TOPIC_SETS`)."""

    stamped: bool = False
    timeout: float = 0.5
    topics: TopicSet = TOPIC_SETS["appmode"]


@dataclass
class Publisher:
    topic: str
    ros_type: str
    key: str
    token: str
    gid: bytes
    zenoh: Any = None
    sequence: int = 0


class RosNode:
    """`session` (started, driving the car) as the node `graph` on `zenoh_session`."""

    def __init__(
        self,
        session: BaseSession,
        zenoh_session: zenoh.Session,
        graph: Node,
        options: Options,
        log: Log,
    ) -> None:
        self.session = session
        self.zenoh = zenoh_session
        self.graph = graph
        self.options = options
        self.log = log
        self.messages = Messages(graph.distro)
        self.odometry = Odometry()
        self._sensed_at = -math.inf
        self._inertial_at = -math.inf
        self._readings = 0
        self._angles: deque[tuple[float, tuple[float, float, float]]] = deque()
        """The last YAW_WINDOW s of B records' roll, pitch and yaw (degrees, REP 103)."""
        self._queue: deque[bytes] = deque(maxlen=QUEUE)
        self._woken = threading.Event()
        """Set by a cmd_vel: the loop takes it at once, not at its next turn."""
        self._lock = threading.Lock()
        self._unattached: str | None = None
        """Why the last cmd_vel dropped for its attachment was (None: none since)."""
        self.received = 0
        """cmd_vel samples taken (for the status and the tests)."""
        self.refused = 0
        """cmd_vel samples that were no Twist."""
        self._seen: dict[str, float] = {"A": -math.inf, "B": -math.inf}
        self._declared: list[Any] = []
        self.publishers: dict[str, Publisher] = {}
        self._said: set[str] = set()
        self.services = Services(zenoh_session, graph, self.messages, self._woken)
        full = f"{graph.namespace.rstrip('/')}/{graph.name}"
        self.parameters = Parameters(session, self.messages.types, full, self._parameter_event)
        self.logger = full.strip("/").replace("/", ".")
        """The node's logger, as rcl names it (`robot1.appmode`)."""

    # ------------------------------------------------------------ the graph

    def declare(self) -> None:
        """The node's token, a token and a Zenoh publisher per topic, the cmd_vel
        subscription and its token (what `ros2 node list` and `topic info` show)."""
        liveliness = self.zenoh.liveliness()
        self._declared.append(liveliness.declare_token(self.graph.node_token()))
        names = self.options.topics
        each = [
            ("odom", names.odom, ODOMETRY, Qos(depth=10)),
            ("tf", names.tf, TF, Qos(depth=100)),
            ("battery", names.battery, names.battery_type, Qos(depth=10)),
            ("imu", names.imu, IMU, Qos(depth=10)),
            ("raw", names.raw, STRING, Qos(depth=10)),
            ("tf_static", names.tf_static, TF, STATIC),
            ("rosout", "/rosout", LOG, rosout.QOS),
            ("parameter_events", "/parameter_events", PARAMETER_EVENT, Qos(depth=1000)),
        ]
        topics = [(name, topic, kind, qos) for name, topic, kind, qos in each if topic]
        for entity_id, (name, topic, ros_type, qos) in enumerate(topics, start=1):
            type_hash = self.messages.type_hash(ros_type)
            token = self.graph.entity_token(entity_id, "MP", topic, ros_type, type_hash, qos)
            key = self.graph.topic_key(topic, ros_type, type_hash)
            publisher = Publisher(topic, ros_type, key, token, gid(token))
            publisher.zenoh = self._publisher(key, qos)
            self._declared += [publisher.zenoh, liveliness.declare_token(token)]
            self.publishers[name] = publisher
        twist = TWIST_STAMPED if self.options.stamped else TWIST
        type_hash = self.messages.type_hash(twist)
        entity_id = len(topics) + 1
        token = self.graph.entity_token(entity_id, "MS", "cmd_vel", twist, type_hash, Qos())
        key = self.graph.topic_key("cmd_vel", twist, type_hash)
        self._declared += [
            self.zenoh.declare_subscriber(key, self._on_cmd_vel),
            liveliness.declare_token(token),
        ]
        self._declared += self.services.declare(SERVICES, entity_id + 1)
        base = self.options.topics.base_frame  # the fixed frame, kept for late subscribers
        if footprint(base) != base:
            fixed = self.messages.transform(STILL, time.time_ns(), base, footprint(base))
            self._put("tf_static", fixed)

    def _publisher(self, key: str, qos: Qos) -> Any:
        """A Zenoh publisher as rmw_zenoh declares one for `qos`: transient local, an
        advanced publisher that keeps its last `depth` samples for late subscribers and
        can be detected (with sample-miss heartbeats, as it is reliable)."""
        if qos.durability is not Durability.TRANSIENT_LOCAL:
            return self.zenoh.declare_publisher(key)
        import zenoh.ext as ext  # the ros extra's, as the session it runs on

        misses = ext.MissDetectionConfig(heartbeat=None, sporadic_heartbeat=HEARTBEAT)
        return ext.declare_advanced_publisher(
            self.zenoh,
            key,
            cache=ext.CacheConfig(max_samples=qos.depth),
            publisher_detection=True,
            sample_miss_detection=misses,
        )

    def _on_cmd_vel(self, sample: zenoh.Sample) -> None:
        """A cmd_vel sample, taken as rmw_zenoh takes it: one with no attachment, or one
        that is not rmw_zenoh's, is dropped (its publisher is no ROS 2 node)."""
        extra = sample.attachment
        try:
            read_attachment(b"" if extra is None else extra.to_bytes())
        except BadAttachment as exc:
            with self._lock:
                self._unattached = str(exc) if extra is not None else "none"
            self._woken.set()
            return
        with self._lock:
            self._queue.append(sample.payload.to_bytes())
        self._woken.set()

    def withdraw(self) -> None:
        """Undeclare every token and entity (ROS sees the node leave)."""
        for declared in reversed(self._declared):
            declared.undeclare()
        self._declared.clear()

    # ------------------------------------------------------------ running

    def run(self, ended: Callable[[], bool]) -> None:
        """Drive the session and the graph until `ended()`."""
        while not ended():
            self.session.tick()
            self._take_commands()
            self._answer()
            self._publish_records()
            self._woken.wait(TICK)
            self._woken.clear()

    def _take_commands(self) -> None:
        with self._lock:
            payloads = list(self._queue)
            self._queue.clear()
            unattached, self._unattached = self._unattached, None
        if unattached is not None:
            self._say_once(
                "attachment",
                f"a cmd_vel whose attachment is not rmw_zenoh's ({unattached}) was dropped, as "
                "rmw_zenoh drops it: its publisher is no ROS 2 node on rmw_zenoh",
            )
        for payload in payloads:
            try:
                forward, left, turn, ignored = self.messages.twist(payload, self.options.stamped)
            except ValueError:
                self.refused += 1
                self._say_once("refused", "a cmd_vel that is no Twist was ignored")
                continue
            try:
                twist = Twist.checked(forward, left, turn)
            except BadTwist as exc:
                self.refused += 1
                self._say_once("nan", f"a cmd_vel was ignored: {exc}")
                continue
            self.received += 1
            self.session.keepalive()
            if ignored:
                self._say_once("3d", "cmd_vel's angular x and y are ignored: a car turns in z")
            self.session.move(twist)

    def _answer(self) -> None:
        """The services' requests, and the sets under way."""
        for request in self.services.take():
            try:
                message = self.messages.request(request.payload, request.ros_type)
            except ValueError as exc:
                self.services.refuse(request)
                self._say_once("bad request", f"a request was left unanswered: {exc}")
                continue
            self.parameters.answer(request.ros_type, message, self._replier(request))
        if self.services.unattached:
            self._say_once(
                "service attachment",
                "a request with no rmw_zenoh attachment was dropped, as rmw_zenoh drops it",
            )
        self.parameters.serve()

    def _parameter_event(self, event: Any) -> None:
        self._put("parameter_events", self.messages.cdr(event, PARAMETER_EVENT))

    def _replier(self, request: Request) -> Callable[[Any], None]:
        return lambda response: self.services.reply(request, response)

    def say(self, text: str) -> None:
        """A line of the node's (or its session's): on stderr and /rosout."""
        self.parameters.said(text)
        self.log(text)
        line = self.messages.log(rosout.level(text), self.logger, text, time.time_ns())
        self._put("rosout", line)

    # ------------------------------------------------------------ the records

    def _publish_records(self) -> None:
        now_ns, now = time.time_ns(), self.session.now()
        sensed = self.session.sensed(self._sensed_at)
        for at, twist in sensed:
            self._sensed_at = at
            self._odometry(twist, at, now_ns - int((now - at) * 1e9))
        inertial = self.session.inertial(self._inertial_at)
        for at, reading in inertial:
            self._inertial_at = at
            self._inertial(reading, now_ns - int((now - at) * 1e9))
        state = self.session.telemetry_state()
        if state is None:
            if self.session.odometry_gap() is not None:  # a chassis senses with no records
                self._say_once("no app", "no APP port beside: odom, battery and imu are not sent")
            return
        for at, event in self._new(state, "A"):
            stamp = now_ns - int((now - at) * 1e9)
            self._raw(event, state, stamp)
            self._battery(self._fields(event, state, "A"), stamp)
            if not sensed and (gap := self.session.odometry_gap()) is not None:
                self._say_once("odom", f"{gap}: odom and tf are not sent")
        for at, event in self._new(state, "B"):
            stamp = now_ns - int((now - at) * 1e9)
            self._raw(event, state, stamp)
            self._attitude(event, state, at, stamp)

    def _new(self, state: HostState, letter: str) -> list[tuple[float, Any]]:
        trace = state.velocities if letter == "A" else state.attitudes
        seen = self._seen[letter]
        fresh = [(at, event) for at, event in reversed(trace.points) if at > seen]
        if fresh:
            self._seen[letter] = fresh[0][0]
        return fresh[::-1]

    def _fields(self, event: Any, state: HostState, letter: str) -> dict[str, tuple[float, Any]]:
        """A record's values by field name, each divided by its scale, with its field."""
        fields = state.layout.a_fields if letter == "A" else state.layout.b_fields
        values = event.values
        return {f.name: (v / f.scale, f) for f, v in zip(fields, values, strict=False)}

    def _odometry(self, twist: Twist, at: float, stamp: int) -> None:
        pose = self.odometry.step(at, twist)
        odom, base = self.options.topics.odom_frame, self.options.topics.base_frame
        variance = self.odometry.variance
        self._put("odom", self.messages.odometry(pose, stamp, odom, base, variance))
        self._put("tf", self.messages.transform(pose, stamp, odom, base))

    def _attitude(self, event: Any, state: HostState, at: float, stamp: int) -> None:
        """The B record's attitude as imu: its orientation, and its rates over the last
        YAW_WINDOW s of records (whole degrees: what the gyro integrated)."""
        fields = self._fields(event, state, "B")
        if all(k in fields for k in ("pitch", "roll", "yaw")):
            # REP 103: the board's yaw is clockwise
            angles = (fields["roll"][0], fields["pitch"][0], -fields["yaw"][0])
            self._angles.append((at, angles))
            while self._angles and self._angles[0][0] < at - YAW_WINDOW:
                self._angles.popleft()
            rates = [yaw_rate([(t, a[axis]) for t, a in self._angles], at) for axis in range(3)]
            roll, pitch, yaw = (math.radians(angle) for angle in angles)
            known = None if None in rates else tuple(math.radians(r or 0.0) for r in rates)
            frame = self.options.topics.imu_frame
            self._put("imu", self.messages.imu(roll, pitch, yaw, stamp, frame, known))
        self._battery(fields, stamp)

    def _inertial(self, reading: Inertial, stamp: int) -> None:
        """An IMU's own rates and accelerations as imu; its battery, every BATTERY_EVERY
        readings."""
        topics, messages = self.options.topics, self.messages
        rates, accelerations = reading.angular_velocity, reading.acceleration
        self._put("imu", messages.imu_raw(rates, accelerations, stamp, topics.imu_frame))
        self._readings += 1
        if reading.volts is None or self._readings % BATTERY_EVERY != 1:
            return
        if topics.battery_type == FLOAT32:
            self._put("battery", messages.float32(reading.volts))
        else:
            self._put("battery", messages.battery_volts(reading.volts, stamp, topics.base_frame))

    def _battery(self, fields: dict[str, tuple[float, Any]], stamp: int) -> None:
        topics, messages = self.options.topics, self.messages
        for value, field in fields.values():
            if not field.battery:
                continue
            if topics.battery_type == FLOAT32:
                self._put("battery", messages.float32(volts_of(value)))
            else:
                self._put("battery", messages.battery(value, stamp, topics.base_frame))

    def _raw(self, event: Any, state: HostState, stamp: int) -> None:
        raw = to_json(event, state.layout).get("raw", "")
        self._put("raw", self.messages.text(str(raw)))

    def _put(self, name: str, payload: bytes) -> None:
        """Publish `payload` as `name` (odom, rosout, …), where the topic set has it."""
        publisher = self.publishers.get(name)
        if publisher is None:
            return
        publisher.sequence += 1
        extra = attachment(publisher.sequence, time.time_ns(), publisher.gid)
        publisher.zenoh.put(payload, attachment=extra)

    def _say_once(self, kind: str, text: str) -> None:
        if kind not in self._said:
            self._said.add(kind)
            self.say(text)
