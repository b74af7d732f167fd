"""A Foxglove WebSocket client written from the protocol's description
(foxglove/ws-protocol: `foxglove.sdk.v1`, JSON control messages, binary message data),
not from the SDK: what Foxglove and Lichtblick do when they open a live connection."""

from __future__ import annotations

import asyncio
import json
import struct
import time
from dataclasses import dataclass, field
from typing import Any

import websockets
from websockets.typing import Subprotocol

SUBPROTOCOLS = [Subprotocol("foxglove.sdk.v1"), Subprotocol("foxglove.websocket.v1")]
MESSAGE_DATA = 0x01


@dataclass
class Seen:
    """What a viewer received: the server's info, the channels by topic, and each
    message as (topic, log time ns, payload)."""

    info: dict[str, Any] = field(default_factory=dict)
    channels: dict[str, dict[str, Any]] = field(default_factory=dict)
    messages: list[tuple[str, int, bytes]] = field(default_factory=list)

    def json_on(self, topic: str) -> list[dict[str, Any]]:
        return [json.loads(data) for t, _, data in self.messages if t == topic]


async def watch(
    url: str, seconds: float, topics: set[str] | None = None, until: Any = None
) -> Seen:
    """Connect, subscribe to every advertised channel (or `topics`), and collect for
    `seconds` (or until `until(seen)` is true)."""
    seen = Seen()
    by_subscription: dict[int, str] = {}
    async with websockets.connect(url, subprotocols=SUBPROTOCOLS, max_size=None) as ws:
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            try:
                frame = await asyncio.wait_for(ws.recv(), left)
            except (
                TimeoutError,
                websockets.ConnectionClosed,
            ):  # the server's end: what it sent stays
                break
            if isinstance(frame, bytes):
                if frame[0] == MESSAGE_DATA:
                    sub, stamp = struct.unpack_from("<IQ", frame, 1)
                    seen.messages.append((by_subscription[sub], stamp, frame[13:]))
                    if until is not None and until(seen):
                        break
                continue
            message = json.loads(frame)
            if message["op"] == "serverInfo":
                seen.info = message
            elif message["op"] == "advertise":
                wanted = []
                for channel in message["channels"]:
                    seen.channels[channel["topic"]] = channel
                    if topics is None or channel["topic"] in topics:
                        sub = len(by_subscription) + 1
                        by_subscription[sub] = channel["topic"]
                        wanted.append({"id": sub, "channelId": channel["id"]})
                if wanted:
                    await ws.send(json.dumps({"op": "subscribe", "subscriptions": wanted}))
    return seen


def watch_sync(url: str, seconds: float, topics: set[str] | None = None, until: Any = None) -> Seen:
    return asyncio.run(watch(url, seconds, topics, until))
