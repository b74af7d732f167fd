"""The node's services on rmw_zenoh's wire (docs/design.md, "Services";
rmw_service_data.cpp of Humble's 0.1.x and Jazzy's 0.2.x alike): per service a complete
queryable on `<domain>/<name>/<type>/<hash>` and an `SS` liveliness token. A request is
a query whose payload is the request's CDR and whose attachment is the client's
sequence number, time and GID (one without is dropped, as rmw_zenoh drops it); the reply
goes to the service's key with the request's sequence number, the client's GID and the
time it is sent.

Queries arrive on Zenoh's threads and wait in a short queue for the node's loop, which
answers them; a set answers later, once the board has shown it."""

from __future__ import annotations

import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from appmode.ros.graph import Node, Qos
from appmode.ros.wire import BadAttachment, attachment, read_attachment

if TYPE_CHECKING:
    import zenoh

    from appmode.ros.messages import Messages

QOS = Qos(depth=1000)
"""rclcpp's parameter services' (rmw_qos_profile_parameters: reliable, volatile, 1000)."""
QUEUE = 64
"""Requests waiting at most (the oldest go unanswered)."""
LARGEST = 64 * 1024
"""Bytes of the largest request taken (the parameter services' are a few hundred)."""


@dataclass
class Request:
    """A request taken: the service's type, the query to answer and its client."""

    ros_type: str
    payload: bytes
    query: Any
    sequence: int
    gid: bytes
    key: str


class Services:
    """The services of the node `graph` on `zenoh_session`."""

    def __init__(
        self, zenoh_session: zenoh.Session, graph: Node, messages: Messages, woken: threading.Event
    ) -> None:
        self.zenoh = zenoh_session
        self.graph = graph
        self.messages = messages
        self._queue: deque[Request] = deque(maxlen=QUEUE)
        self._lock = threading.Lock()
        self.unattached = 0
        """Requests dropped for their attachment (not a ROS 2 client's)."""
        self.woken = woken
        """Set when a request arrives: the node's loop takes it at once."""

    def declare(self, services: dict[str, str], first_id: int) -> list[Any]:
        """A queryable and a token per service (name → type), entity ids from `first_id`."""
        declared: list[Any] = []
        liveliness = self.zenoh.liveliness()
        for entity_id, (name, ros_type) in enumerate(services.items(), start=first_id):
            type_hash = self.messages.service_hash(ros_type)
            key = self.graph.topic_key(name, ros_type, type_hash)
            token = self.graph.entity_token(entity_id, "SS", name, ros_type, type_hash, QOS)

            def taken(query: zenoh.Query, ros_type: str = ros_type, key: str = key) -> None:
                self._take(query, ros_type, key)

            declared += [
                self.zenoh.declare_queryable(key, taken, complete=True),
                liveliness.declare_token(token),
            ]
        return declared

    def _take(self, query: Any, ros_type: str, key: str) -> None:
        extra = query.attachment
        try:
            sequence, _, gid = read_attachment(b"" if extra is None else extra.to_bytes())
        except BadAttachment:
            with self._lock:
                self.unattached += 1
            query.drop()
            return
        payload = b"" if query.payload is None else query.payload.to_bytes()
        if len(payload) > LARGEST:
            query.drop()
            return
        with self._lock:
            self._queue.append(Request(ros_type, payload, query, sequence, gid, key))
        self.woken.set()

    def take(self) -> list[Request]:
        with self._lock:
            requests = list(self._queue)
            self._queue.clear()
        return requests

    def reply(self, request: Request, response: Any) -> None:
        """Answer `request` with `response` (a message of its service's response type)."""
        payload = self.messages.cdr(response, f"{request.ros_type}_Response")
        extra = attachment(request.sequence, time.time_ns(), request.gid)
        try:
            request.query.reply(request.key, payload, attachment=extra)
        finally:
            request.query.drop()

    def refuse(self, request: Request) -> None:
        """Leave `request` unanswered (its payload is no request of its type)."""
        request.query.drop()
