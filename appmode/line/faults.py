"""Faults a Bluetooth serial link really has, injected on purpose.

`Faults` transforms the bytes of one direction, with no I/O: it drops, duplicates and
corrupts bytes and injects HC-05-style module chatter, from a seeded generator so that a
failing case replays. `FaultyLine` adds delay and splitting in time. `FaultyPort` wraps
any pyserial port with both, for tests; `sim://?faults=…` uses them inside the simulated
link. The spec is `name:value` pairs separated by commas:

    drop:0.01,dup:0.01,corrupt:0.01,chatter:0.002,split:1,delay:0.02,seed:7
"""

from __future__ import annotations

import random
import time
from collections import deque
from dataclasses import dataclass, fields
from typing import Any

CHATTER = (
    b"+DISC:SUCCESS\r\n",
    b"+CONNECTING<<00:11:22:33:44:55>>\r\n",
    b"OK\r\n",
    b"+CONNECTED\r\n",
)


@dataclass(frozen=True, slots=True)
class FaultSpec:
    drop: float = 0.0
    """Probability that a byte is lost."""
    dup: float = 0.0
    """Probability that a byte arrives twice."""
    corrupt: float = 0.0
    """Probability that a byte is replaced by a random one."""
    chatter: float = 0.0
    """Probability, for each byte, that a module status line is slipped in before it."""
    split: float = 0.0
    """Probability that a chunk is delivered in two pieces at different times."""
    delay: float = 0.0
    """Extra latency of a chunk: uniform in 0…delay seconds (order is kept)."""
    seed: int = 0

    @classmethod
    def parse(cls, text: str) -> FaultSpec:
        """`drop:0.01,corrupt:0.02,seed:3`; ValueError says what is wrong."""
        known = {f.name: f for f in fields(cls)}
        values: dict[str, Any] = {}
        for part in filter(None, text.split(",")):
            name, sep, value = part.partition(":")
            if name not in known or not sep:
                raise ValueError(f"fault {part!r}: use name:value with names {', '.join(known)}")
            try:
                values[name] = int(value) if name == "seed" else float(value)
            except ValueError:
                raise ValueError(f"fault {part!r}: {value!r} is not a number") from None
            if name not in ("seed", "delay") and not 0 <= values[name] <= 1:
                raise ValueError(f"fault {part!r}: a probability is between 0 and 1")
            if name == "delay" and not 0 <= values[name] <= 10:
                raise ValueError(f"fault {part!r}: delay is seconds, 0 to 10")
        return cls(**values)

    @property
    def active(self) -> bool:
        return any((self.drop, self.dup, self.corrupt, self.chatter, self.split, self.delay))


@dataclass(slots=True)
class FaultCounts:
    dropped: int = 0
    duplicated: int = 0
    corrupted: int = 0
    chatter: int = 0


class Faults:
    """Byte faults for one direction."""

    def __init__(self, spec: FaultSpec, rng: random.Random) -> None:
        self.spec = spec
        self.rng = rng
        self.counts = FaultCounts()

    def apply(self, data: bytes) -> bytes:
        spec, rng, counts = self.spec, self.rng, self.counts
        out = bytearray()
        for byte in data:
            if spec.chatter and rng.random() < spec.chatter:
                counts.chatter += 1
                out += rng.choice(CHATTER)
            roll = rng.random()
            if roll < spec.drop:
                counts.dropped += 1
                continue
            if roll < spec.drop + spec.corrupt:
                counts.corrupted += 1
                byte = rng.randrange(256)
            out.append(byte)
            if rng.random() < spec.dup:
                counts.duplicated += 1
                out.append(byte)
        return bytes(out)


class FaultyLine:
    """Faulted bytes released over time: delayed (in order) and split into pieces."""

    def __init__(self, spec: FaultSpec, rng: random.Random) -> None:
        self.faults = Faults(spec, rng)
        self._queue: deque[tuple[float, bytes]] = deque()
        self._last = 0.0

    def push(self, data: bytes, now: float) -> None:
        spec, rng = self.faults.spec, self.faults.rng
        data = self.faults.apply(data)
        if not data:
            return
        pieces = [data]
        if spec.split and len(data) > 1 and rng.random() < spec.split:
            cut = rng.randrange(1, len(data))
            pieces = [data[:cut], data[cut:]]
        for piece in pieces:
            release = max(self._last, now + rng.uniform(0.0, spec.delay))
            self._last = release
            self._queue.append((release, piece))

    def take(self, now: float) -> bytes:
        out = bytearray()
        while self._queue and self._queue[0][0] <= now:
            out += self._queue.popleft()[1]
        return bytes(out)

    def next_due(self) -> float | None:
        return self._queue[0][0] if self._queue else None


class FaultyPort:
    """Any pyserial port behind a faulty link (both directions), for tests."""

    def __init__(self, port: Any, spec: FaultSpec) -> None:
        rng = random.Random(spec.seed)
        self.port = port
        self.to_port = FaultyLine(spec, rng)
        self.from_port = FaultyLine(spec, rng)
        self._rx = bytearray()

    def _pump(self) -> None:
        now = time.monotonic()
        waiting = self.port.in_waiting
        if waiting:
            self.from_port.push(self.port.read(waiting), now)
        self._rx += self.from_port.take(now)
        sent = self.to_port.take(now)
        if sent:
            self.port.write(sent)

    @property
    def timeout(self) -> float | None:
        """The read timeout of the port behind."""
        timeout: float | None = self.port.timeout
        return timeout

    @property
    def in_waiting(self) -> int:
        self._pump()
        return len(self._rx)

    def read(self, size: int = 1) -> bytes:
        deadline = time.monotonic() + (self.timeout or 0.0)
        self._pump()
        while len(self._rx) < size and time.monotonic() < deadline:
            time.sleep(0.001)
            self._pump()
        data = bytes(self._rx[:size])
        del self._rx[:size]
        return data

    def write(self, data: bytes) -> int:
        self.to_port.push(bytes(data), time.monotonic())
        self._pump()
        return len(data)

    def flush(self) -> None:
        end = time.monotonic() + 1.0
        while self.to_port.next_due() is not None and time.monotonic() < end:
            time.sleep(0.001)
            self._pump()
        self.port.flush()

    def close(self) -> None:
        self.port.close()
