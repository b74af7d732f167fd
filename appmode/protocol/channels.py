"""What a viewer (Foxglove, an MCAP file) shows of a session, with no I/O: each decoded
unit as a JSON message on a channel named for what it is — the records by kind, with
the profile's field names and units (`/app/A`, `/app/B`, `/app/C`), what the host sent
(`/app/commands`, `/uart2/commands`), what UART2 answered (`/uart2/replies`) — and the
car's dead-reckoned pose (`/pose` and `/tf`, in foxglove's PoseInFrame and
FrameTransform shapes, labelled as dead reckoning). One table of the channels; every
schema a JSON schema, so a plot panel lists the fields by name, with their units."""

from __future__ import annotations

import math
import threading
from collections import deque
from dataclasses import dataclass
from typing import Any, Protocol

from appmode.protocol import app, chassis, control
from appmode.protocol.control_view import view
from appmode.protocol.escaping import escape
from appmode.protocol.layouts import Layout
from appmode.protocol.odometry import Odometry, Pose2D
from appmode.protocol.params import DriveType
from appmode.protocol.reader import (
    RECEIVED,
    RECEIVED2,
    RECEIVED_CHASSIS,
    SENT,
    SENT2,
    SENT_CHASSIS,
)
from appmode.protocol.sensed import Sensing, signs_in_force, yaw_rate

YAWS = 64
"""B records' yaws kept for a turn rate (a YAW_WINDOW's worth, and more)."""
POSE_FRAME = "odom"
"""The frame the dead-reckoned pose is in (its origin: where the session began)."""
BASE_FRAME = "base_link"
OBJECT: dict[str, Any] = {"type": "object"}
RAW = {
    ">": "/raw/app/sent",
    "<": "/raw/app/received",
    "2>": "/raw/uart2/sent",
    "2<": "/raw/uart2/received",
    "c>": "/raw/chassis/sent",
    "c<": "/raw/chassis/received",
}
"""Each direction's raw channel: a message a unit, its bytes as they went."""
RAW_SCHEMA = {
    "type": "object",
    "properties": {
        "text": {"type": "string", "description": "the bytes as transcripts show them"},
        "hex": {"type": "string", "description": "the bytes, exactly"},
        "length": {"type": "integer"},
    },
}
IN_FORCE = "/session/in_force"
LOG = "/log"
"""What a session says, and a line per unit (`foxglove.Log`)."""
CMD_VEL = "/cmd_vel"
"""Where a viewer that may drive publishes its twists (`--foxglove-drive`)."""
IN_FORCE_SCHEMA = {
    "type": "object",
    "properties": {
        "command": {"type": "string", "description": "the letter or frame in force"},
        "text": {"type": "string"},
        "moving": {"type": "boolean"},
    },
}


@dataclass(frozen=True, slots=True)
class ChannelSpec:
    topic: str
    schema_name: str
    schema: dict[str, Any]
    description: str


def _number_fields(fields: list[tuple[str, str]]) -> dict[str, Any]:
    properties = {name: {"type": "number", "description": unit} for name, unit in fields}
    return {"type": "object", "properties": {**properties, "raw": {"type": "string"}}}


_TIME = {
    "type": "object",
    "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}},
}
_VECTOR = {"type": "object", "properties": {k: {"type": "number"} for k in "xyz"}}
_QUATERNION = {"type": "object", "properties": {k: {"type": "number"} for k in "xyzw"}}
POSE_SCHEMA = {
    "title": "foxglove.PoseInFrame",
    "type": "object",
    "properties": {
        "timestamp": _TIME,
        "frame_id": {"type": "string"},
        "pose": {
            "type": "object",
            "properties": {"position": _VECTOR, "orientation": _QUATERNION},
        },
    },
}
TRANSFORM_SCHEMA = {
    "title": "foxglove.FrameTransform",
    "type": "object",
    "properties": {
        "timestamp": _TIME,
        "parent_frame_id": {"type": "string"},
        "child_frame_id": {"type": "string"},
        "translation": _VECTOR,
        "rotation": _QUATERNION,
    },
}


_TRIPLE = {"type": "array", "items": {"type": "number"}}
CHASSIS_STATUS = {
    "type": "object",
    "properties": {
        "forward": {"type": "number", "description": "m/s"},
        "left": {"type": "number", "description": "m/s"},
        "turn": {"type": "number", "description": "rad/s counter-clockwise"},
        "flag_stop": {"type": "integer", "description": "1: booting, or stopped by the board"},
        "acceleration": {**_TRIPLE, "description": "m/s², x forward, y left, z up"},
        "angular_velocity": {**_TRIPLE, "description": "rad/s about x, y, z"},
        "volts": {"type": "number", "description": "the battery, V"},
        "raw": {"type": "string"},
    },
}
_WHEELS = {"type": "array", "items": {"type": "integer"}}
ENCODERS = {
    "type": "object",
    "properties": {
        "targets": {**_WHEELS, "description": "each wheel's target (encoder counts)"},
        "actuals": {**_WHEELS, "description": "each wheel's measured speed (encoder counts)"},
        "raw": {"type": "string"},
    },
}


def channels(layout: Layout) -> dict[str, ChannelSpec]:
    """Every channel, by topic, with `layout`'s record fields."""
    a = [(f.name, f.unit) for f in layout.a_fields]
    b = [(f.name, f.unit) for f in layout.b_fields]
    c = [(p.name, p.label) for p in layout.params]
    specs = [
        ChannelSpec("/app/A", "appmode.A", _number_fields(a), "A records: motion"),
        ChannelSpec("/app/B", "appmode.B", _number_fields(b), "B records: attitude, battery"),
        ChannelSpec("/app/C", "appmode.C", _number_fields(c), "C records: the parameters"),
        ChannelSpec("/app/other", "appmode.event", OBJECT, "other bytes from the board"),
        ChannelSpec("/app/commands", "appmode.event", OBJECT, "letters and frames sent"),
        ChannelSpec("/uart2/commands", "appmode.event", OBJECT, "control-port frames sent"),
        ChannelSpec("/uart2/replies", "appmode.event", OBJECT, "control-port replies"),
        ChannelSpec("/uart2/encoders", "appmode.encoders", ENCODERS, "encoder reports"),
        ChannelSpec("/chassis/commands", "appmode.event", OBJECT, "chassis frames sent"),
        ChannelSpec(
            "/chassis/status", "appmode.chassis.status", CHASSIS_STATUS, "chassis status in SI"
        ),
        ChannelSpec("/pose", "foxglove.PoseInFrame", POSE_SCHEMA, "dead reckoning"),
        ChannelSpec("/tf", "foxglove.FrameTransform", TRANSFORM_SCHEMA, "dead reckoning"),
        ChannelSpec(IN_FORCE, "appmode.in_force", IN_FORCE_SCHEMA, "the command in force"),
    ]
    return {spec.topic: spec for spec in specs}


class Decoded:
    """Decoded units, in `layout`'s terms, as (topic, JSON message) pairs; the pose from
    each A record that says the car's twist (`protocol.sensed`: magnitudes signed by the
    control port's frame in force, where `drive` says how; a turn from the yaw)."""

    def __init__(self, layout: Layout, drive: DriveType | None = None) -> None:
        self.layout = layout
        self.odometry = Odometry()
        self._sensing = Sensing(layout)
        self._drive = drive
        self._signs: tuple[float, float, float] | None = None  # until a frame says
        self._yaws: deque[tuple[float, float]] = deque(maxlen=YAWS)

    def unit(self, time: float, direction: str, event: Any) -> list[tuple[str, dict[str, Any]]]:
        """The messages one decoded unit makes (`time`: seconds, the session's)."""
        found = self._unit(time, direction, event)
        moves = _moves(event) if direction in (SENT, SENT2, SENT_CHASSIS) else None
        if moves is not None:
            text = view(event, self.layout)[1]
            command = escape(event.raw)
            found.append((IN_FORCE, {"command": command, "text": text, "moving": moves}))
        return found

    def _unit(self, time: float, direction: str, event: Any) -> list[tuple[str, dict[str, Any]]]:
        if direction in (SENT_CHASSIS, RECEIVED_CHASSIS):
            return self._chassis(time, direction, event)
        body = view(event, self.layout)[0]
        if direction == SENT:
            return [("/app/commands", body)]
        if direction == SENT2:
            if isinstance(event, control.VelocityFrame | control.MotorFrame):
                self._signs = signs_in_force(event, self._drive)
            return [("/uart2/commands", body)]
        if direction == RECEIVED2:
            encoders = isinstance(event, control.EncoderReport)
            return [("/uart2/encoders" if encoders else "/uart2/replies", body)]
        if direction != RECEIVED or not isinstance(event, app.RECORDS):
            return [("/app/other", body)]
        letter, values = event.letter, event.values
        if letter not in "ABC":
            return [("/app/other", body)]
        found = [(f"/app/{letter}", self._scaled(letter, values, event.raw))]
        if letter == "B" and self._sensing.yaw is not None:
            self._yaws.append((time, values[self._sensing.yaw]))
        rate = yaw_rate(self._yaws, time) if self._sensing.turn_from_yaw else None
        twist = self._sensing.twist(values, self._signs, rate) if letter == "A" else None
        if twist is not None:
            pose = self.odometry.step(time, twist)
            found += [("/pose", pose_message(pose, time)), ("/tf", transform(pose, time))]
        return found

    def _chassis(
        self, time: float, direction: str, event: chassis.Event
    ) -> list[tuple[str, dict[str, Any]]]:
        """A chassis port's frame in SI; a status frame also moves the pose."""
        body = chassis.as_json(event)
        if direction == SENT_CHASSIS:
            return [("/chassis/commands", body)]
        if not isinstance(event, chassis.Status):
            return [("/app/other", body)]
        pose = self.odometry.step(time, event.twist)
        return [
            ("/chassis/status", body),
            ("/pose", pose_message(pose, time)),
            ("/tf", transform(pose, time)),
        ]

    def _scaled(self, letter: str, values: tuple[int, ...], raw: bytes) -> dict[str, Any]:
        """A record's values in the user's units (each field's value over its scale)."""
        layout = self.layout
        if letter == "C":
            scales = [(p.name, p.scale) for p in layout.params]
        else:
            fields = layout.a_fields if letter == "A" else layout.b_fields
            scales = [(f.name, f.scale) for f in fields]
        body: dict[str, Any] = {
            name: value if scale == 1 else value / scale
            for (name, scale), value in zip(scales, values, strict=False)
        }
        body["raw"] = raw.decode("latin-1")
        return body


def _moves(event: Any) -> bool | None:
    """Whether a command sets the car moving (True), stops it (False), or neither."""
    if isinstance(event, chassis.Command):
        return not event.twist.still
    if isinstance(event, app.Move):
        return event.direction != 0
    if isinstance(event, app.Stop):
        return False
    if isinstance(event, control.VelocityFrame | control.MotorFrame):
        return any(event.values) and not (isinstance(event, control.VelocityFrame) and event.angle)
    if isinstance(event, control.PositionFrame):
        return any((event.x, event.y, event.z))
    return None


def _stamp(time: float) -> dict[str, int]:
    ns = round(time * 1e9)
    return {"sec": ns // 10**9, "nsec": ns % 10**9}


def _yaw(yaw: float) -> dict[str, float]:
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}


def pose_message(pose: Pose2D, time: float) -> dict[str, Any]:
    return {
        "timestamp": _stamp(time),
        "frame_id": POSE_FRAME,
        "pose": {"position": {"x": pose.x, "y": pose.y, "z": 0.0}, "orientation": _yaw(pose.yaw)},
    }


def transform(pose: Pose2D, time: float) -> dict[str, Any]:
    return {
        "timestamp": _stamp(time),
        "parent_frame_id": POSE_FRAME,
        "child_frame_id": BASE_FRAME,
        "translation": {"x": pose.x, "y": pose.y, "z": 0.0},
        "rotation": _yaw(pose.yaw),
    }


class Viewer(Protocol):
    """A live view of a session: fed its bytes as a tap and what it says, never waiting
    (it queues, bounded, and drops what does not fit)."""

    epoch: float
    watched: threading.Event
    """Set once someone watches (a replay to a viewer alone waits for it)."""

    def __call__(self, direction: str, time: float, data: bytes) -> None: ...

    def note(self, text: str) -> None: ...
