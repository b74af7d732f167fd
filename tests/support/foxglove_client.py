"""A Foxglove WebSocket client written from the protocol's description
(foxglove/ws-protocol: `foxglove.sdk.v1`, JSON control messages, binary message data),
not from the SDK: what Foxglove and Lichtblick do when they open a live connection."""

from __future__ import annotations

import asyncio
import json
import re
import struct
import subprocess
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import websockets
from websockets.typing import Subprotocol

from tests.support.processes import ROOT, appmode_cmd

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


CLIENT_MESSAGE_DATA = 0x01


class Driver:
    """A viewer that drives and tunes, as Foxglove's Teleop and Parameters panels do:
    it advertises a channel, publishes JSON on it, asks for and sets parameters; every
    text message the server sends is kept (`said`), in order."""

    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.said: list[dict[str, Any]] = []
        self.info: dict[str, Any] = {}
        self._reader = asyncio.get_running_loop().create_task(self._read())

    @classmethod
    async def open(cls, url: str) -> Driver:
        ws = await websockets.connect(url, subprotocols=SUBPROTOCOLS, max_size=None)
        driver = cls(ws)
        await driver.wait_for(lambda m: m.get("op") == "serverInfo")
        return driver

    async def _read(self) -> None:
        try:
            async for frame in self.ws:
                if isinstance(frame, str):
                    message = json.loads(frame)
                    if message.get("op") == "serverInfo":
                        self.info = message
                    self.said.append(message)
        except websockets.ConnectionClosed:
            pass

    async def wait_for(self, check: Any, seconds: float = 5.0) -> dict[str, Any]:
        """The first message the server said (or says within `seconds`) that `check` takes."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            for message in self.said:
                if check(message):
                    return message
            await asyncio.sleep(0.02)
        raise AssertionError(f"the server did not say it in {seconds} s: {self.said[-5:]}")

    async def advertise(self, channel: int, topic: str = "/cmd_vel") -> None:
        await self.send(
            {
                "op": "advertise",
                "channels": [
                    {
                        "id": channel,
                        "topic": topic,
                        "encoding": "json",
                        "schemaName": "geometry_msgs/msg/Twist",
                    }
                ],
            }
        )

    async def publish(self, channel: int, message: Any) -> None:
        data = message if isinstance(message, bytes) else json.dumps(message).encode()
        await self.ws.send(struct.pack("<BI", CLIENT_MESSAGE_DATA, channel) + data)

    async def twist(self, channel: int, x: float, y: float = 0.0, z: float = 0.0) -> None:
        zero = {"x": 0.0, "y": 0.0, "z": 0.0}
        await self.publish(
            channel, {"linear": {**zero, "x": x, "y": y}, "angular": {**zero, "z": z}}
        )

    async def send(self, message: dict[str, Any]) -> None:
        await self.ws.send(json.dumps(message))

    async def close(self) -> None:
        await self.ws.close()
        await self._reader


@contextmanager
def serving(*args: str, stdin: str | None = None) -> Iterator[tuple[subprocess.Popen[str], str]]:
    """`appmode ARGS --foxglove 0`, and the ws:// URL it says; `stdin` fed after 0.3 s."""
    proc = subprocess.Popen(
        appmode_cmd(*args, "--foxglove", "0"),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        assert proc.stderr is not None and proc.stdin is not None
        said = ""
        while (line := proc.stderr.readline()) and "ws://" not in line:
            said += line
        found = re.search(r"ws://\S+", line)
        assert found, said
        if stdin is not None:
            writer = proc.stdin

            def feed() -> None:
                time.sleep(0.3)
                writer.write(stdin)
                writer.close()

            threading.Thread(target=feed, daemon=True).start()
        yield proc, found.group(0)
    finally:
        if proc.poll() is None:
            proc.terminate()
        proc.wait(15)


async def malformed(url: str, count: int = 20) -> None:
    """A viewer that sends `count` unknown ops (with a terminal's escape sequence) and
    non-JSON twists, then is killed (its connection dropped without a close)."""
    driver = await Driver.open(url)
    await driver.advertise(1)
    for number in range(count):
        await driver.send({"op": f"bogus{number}\x1b[2J"})  # an escape sequence, too
        await driver.publish(1, b"\xff not json")
    assert driver.ws.transport is not None
    driver.ws.transport.abort()
