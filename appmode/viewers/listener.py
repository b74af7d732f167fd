"""What viewers send a live view's server (the foxglove SDK calls it on its own threads):
a subscription (the view is watched), and with `--foxglove-drive` the Teleop panel's
twists on CMD_VEL and the Parameters panel's reads and sets, handed to the session's
desk (`session.desk`); the SDK's own log lines, one of a kind at a time, as notes."""

from __future__ import annotations

import json
import logging
import math
import threading
from collections.abc import Callable
from typing import Any

from foxglove.websocket import (
    Capability,
    ChannelView,
    Client,
    ClientChannel,
    Parameter,
    ServerListener,
)

from appmode.protocol.channels import CMD_VEL
from appmode.protocol.twist import BadTwist, Twist
from appmode.session.desk import Desk, Values
from appmode.text import escaped
from appmode.throttle import Throttle

DRIVING = [Capability.ClientPublish, Capability.Parameters]
"""What the server offers viewers that may drive and tune."""
ENCODINGS = ["json"]
"""The message encodings the server takes from viewers."""
MAX_MESSAGE = 4096
"""Bytes a viewer's twist may take (a Twist in JSON is some 120)."""
CHANNELS = 256
"""Channels viewers may advertise at once (the rest are ignored)."""


class Listener(ServerListener):
    """The server's listener: `watched` set when a viewer subscribes; with a `desk`,
    what viewers publish and ask of the parameters; what went wrong is said by the
    session through the desk, or else as a `note` to the viewers."""

    def __init__(
        self, watched: threading.Event, desk: Desk | None, note: Callable[[str], None]
    ) -> None:
        self._watched = watched
        self._desk = desk
        self._throttle = Throttle()
        self._note = note
        self._lock = threading.Lock()
        self._drives: dict[tuple[int, int], bool] = {}
        """Each advertised channel (client, channel): whether it is CMD_VEL."""

    def say(self, kind: str, text: str) -> None:
        """`text` as a note, one of its `kind` every so often (`Throttle`)."""
        left_out = self._throttle.allow(kind)
        if left_out is None:
            return
        text += f" ({left_out:,} more like it left out)" if left_out else ""
        if self._desk is not None:
            self._desk.tell(text)  # the session says it (and its viewers show it)
        else:
            self._note(text)

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        self._watched.set()

    def on_client_advertise(self, client: Client, channel: ClientChannel) -> None:
        drives = channel.topic == CMD_VEL
        with self._lock:
            if len(self._drives) >= CHANNELS:
                return
            self._drives[(client.id, channel.id)] = drives
        if self._desk is None:
            return
        if not drives:
            self.say(
                "topic",
                f"viewer {client.id}: {escaped(channel.topic[:80])} is not "
                f"taken (appmode drives on {CMD_VEL})",
            )

    def on_client_unadvertise(self, client: Client, client_channel_id: int) -> None:
        with self._lock:
            drove = self._drives.pop((client.id, client_channel_id), False)
        if drove and self._desk is not None:
            self._desk.left(client.id)

    def on_message_data(self, client: Client, client_channel_id: int, data: bytes) -> None:
        with self._lock:
            drives = self._drives.get((client.id, client_channel_id), False)
        if not drives or self._desk is None:
            return
        try:
            twist = twist_of(data)
        except ValueError as exc:
            self.say("twist", f"viewer {client.id}: a {CMD_VEL} message was ignored: {exc}")
            return
        self._desk.twist(client.id, twist)

    def on_get_parameters(
        self, client: Client, param_names: list[str], request_id: str | None = None
    ) -> list[Parameter]:
        if self._desk is None:
            return []
        return listed(self._desk.values(), param_names)

    def on_set_parameters(
        self, client: Client, parameters: list[Parameter], request_id: str | None = None
    ) -> list[Parameter]:
        """Each set waits its turn on the session; the values as they stand now are the
        answer, and the values read back follow when the sets are done."""
        if self._desk is None:
            return []
        asked = []
        for parameter in parameters[:16]:
            value = parameter.get_value()
            if isinstance(value, bool) or not isinstance(value, int | float):
                self.say(
                    "parameter",
                    f"viewer {client.id}: {escaped(parameter.name[:40])} takes a number",
                )
                continue
            asked.append((escaped(parameter.name[:40]), _number(value)))
        self._desk.set(asked)
        return listed(self._desk.values(), [p.name for p in parameters])


def listed(values: Values, names: list[str]) -> list[Parameter]:
    """The parameters named (all when none is), with their values."""
    return [Parameter(name, value=v) for name, v in values.items() if not names or name in names]


def _number(value: float) -> str:
    """A viewer's number as the user's text (800.0: `800`)."""
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)


def twist_of(data: bytes) -> Twist:
    """A geometry_msgs Twist (or TwistStamped) in JSON as a twist; ValueError if it is none."""
    if len(data) > MAX_MESSAGE:
        raise ValueError(f"over {MAX_MESSAGE} bytes")
    try:
        message = json.loads(data)
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
        raise ValueError("it is no JSON") from None
    if isinstance(message, dict) and isinstance(message.get("twist"), dict):
        message = message["twist"]  # TwistStamped
    if not isinstance(message, dict):
        raise ValueError("it is no Twist (linear and angular)")
    linear, angular = message.get("linear", {}), message.get("angular", {})
    if not isinstance(linear, dict) or not isinstance(angular, dict) or not (linear or angular):
        raise ValueError("it is no Twist (linear and angular)")
    parts = [_part(linear, "x"), _part(linear, "y"), _part(angular, "z")]
    try:
        return Twist.checked(*parts)
    except BadTwist as exc:
        raise ValueError(str(exc)) from None


def _part(vector: dict[str, Any], axis: str) -> float:
    value = vector.get(axis, 0.0)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"its {axis} is no number")
    if isinstance(value, int) and abs(value) > 10**6:
        raise ValueError(f"its {axis} is out of range")
    return float(value) if math.isfinite(value) else math.nan


class SdkLog(logging.Handler):
    """The SDK's own log lines (a viewer gone without closing, a malformed message), as
    the listener's throttled notes: never over a console's screen."""

    def __init__(self, listener: Listener) -> None:
        super().__init__(logging.WARNING)
        self._listener = listener

    def emit(self, record: logging.LogRecord) -> None:
        text = " ".join(record.getMessage().split())[:200]  # a client's text in it, too:
        shown = escaped(text)
        self._listener.say(record.name + text[:30], f"foxglove: {shown}")
