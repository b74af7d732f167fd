"""`zenoh://NAME?connect=…&key=…`: a car another machine shares (`appmode share`), as a
pyserial port, so that every host and session drives it as a local one.

What the car's port sends arrives with the car's own times of it (a recording made here
is timed at the car); a write is a query the car's host answers when the bytes have left
for the car (the reply's time is the car's), or refuses (another client drives, its
link to the car is down). While the port is open it beats (`names.Keys.alive`) and holds
a liveliness token: when both stop — this process killed, this machine asleep, the
network cut — the car's host stops the car itself. When the car's host is gone, or
another client takes the driving over, the port says so as a lost link."""

from __future__ import annotations

import contextlib
import json
import os
import secrets
import socket
import threading
import time
from collections import deque
from typing import TYPE_CHECKING, Any

import serial
from serial import SerialException

from appmode.errors import AppmodeError
from appmode.host import far
from appmode.net.asked import json_object
from appmode.net.beats import BeatSender
from appmode.net.config import Tls, close_session, open_session, zenoh_module
from appmode.net.fleet import ask, token
from appmode.net.names import Keys, concrete
from appmode.net.proof import Prover
from appmode.net.signature import Trust
from appmode.net.stamps import unstamp
from appmode.ports.modemless import Modemless
from appmode.ports.remote import RemoteTarget, WriteRefused
from appmode.ports.urls import port_target
from appmode.protocol.reader import RECEIVED_DIRECTIONS
from appmode.text import escaped

if TYPE_CHECKING:
    import zenoh

BEAT = 0.05
"""Seconds between two heartbeats, each on Zenoh and on UDP (`beats`): the car's host
stops the car after 0.3 s without one, and a link losing 5 % of its packets loses six
in a row once in 60 million."""
FIND = 3.0
"""Seconds to wait for the car's host to answer when the port opens."""
SILENT = 3.0
"""Seconds without a word from the car's host (it publishes its info every second) after
which the port is lost: the network between is cut (its host stops the car)."""
WRITE_TIMEOUT = 2.0
"""Seconds a write waits for the car's host to say the bytes left (a round trip, and
TCP's resending of a packet lost on the way: 0.3 + 0.6 s over a link of 150 ms each
way); bytes that reach it later are not written."""
REPLAY = 1.0
"""Seconds an event may be older than the newest heard (the car's host says them from
several threads); an older one is a replay."""
CLOSING = 0.3
"""Seconds the share's token may go before its last word, that it ends, is heard."""
LINK_DOWN = (
    "the car's host has lost its serial link to the car: check the car is on and its "
    "cable or adapter on that machine (appmode share says what it lost in its log)"
)


def new_client() -> str:
    """A link's client id: its machine, its process, and a token of the link's own (a
    client revoked by the car's host drives again on its next link, never this one)."""
    return f"{socket.gethostname()}-{os.getpid()}-{secrets.token_hex(3)}"


"""This process, as the car's host knows it (its machine's name first)."""
_TOOK: set[str] = set()
"""The cars this process took the driving of (take=1 takes once: a reconnection after
another client took it back does not take it again)."""


class RemoteSerial(Modemless):
    """A shared car's port (`port=app`, the default, or `port=uart2`)."""

    target: Any = None
    """The board to open, parsed once (`ports.urls.port_target`)."""

    def open(self) -> None:
        if self._port is None:
            raise SerialException("port must be configured before use")
        zenoh_module_or_serial_error()
        target = port_target(self)
        remote = target.remote
        if not isinstance(remote, RemoteTarget):
            raise SerialException(f"{target.url!r} names no shared car")
        self._remote, self._side = remote, target.sim_port
        self._keys = Keys(remote.name)
        self._client = new_client()
        self._trust = Trust(remote.key, remote.host_id)
        """Who speaks for the car: only what its host signed is heard."""
        self._said_at = 0.0
        """The car's time of the newest event heard (an older one is a replay)."""
        self._prover = Prover()
        """What proves this client's heartbeats and writes its own, once it drives."""
        self._ready = threading.Condition()
        self._rx = bytearray()
        self._rx_times: deque[list[float]] = deque()
        self._heard = 0.0
        self._joined = self._side != "app"
        """Whether the car's stream has been joined (the APP port's, at a record's
        start: bytes before the first `{` are the tail of a record sent before)."""
        self._host_heard = time.monotonic()
        self._lost: str | None = None
        self._closing = threading.Event()
        """Set when the share said it ends (`_host_closed`: having stopped the car)."""
        self._host_closed = False
        self._closed_at = 0.0
        self.host_stopped_car = False
        """The car's host stopped the car last (and nothing was written since), or ended
        its share having stopped it (`Link.stopped_far`)."""
        self._far_stops: deque[tuple[str, bool]] = deque(maxlen=8)
        self.latency: float | None = None
        """Milliseconds the last write took to be acknowledged by the car's host."""
        self.written_at = 0.0
        self.read_runs: list[tuple[float, int]] = []
        try:
            self._session = open_session(
                "client",
                remote.key,
                connect=remote.connect,
                scout=not remote.connect,
                tls=None if remote.ca is None else Tls(root_ca=remote.ca),
            )
        except AppmodeError as exc:
            raise SerialException(str(exc)) from None
        try:
            self._found()
            self._declare()
        except BaseException:
            close_session(self._session)
            raise
        self.is_open = True

    def _where(self) -> str:
        return ", ".join(self._remote.connect) or "this network (scouting)"

    def _found(self) -> None:
        """The car's host answers and shares this port; the car's clock, from its info."""
        name = self._remote.name
        sent, asked = time.monotonic(), token()
        info = self._trust.answer(ask(self._session, self._keys.info, asked, FIND), asked)
        if info is None or info.get("name") != name:
            raise SerialException(
                f"no car named {name} answers at {self._where()}: is 'appmode share --name "
                f"{name}' running there, with this key?{self._trust.refusal()}"
            )
        self.simulated = info.get("simulated") is True
        """The car shared is a simulated board (the views say so)."""
        self.car_link_down: str | None = None
        """Why nothing can come from the car (its host lost its link to this port)."""
        self._links_said(info.get("links"))
        if self._side not in info.get("ports", ()):
            shared = ", ".join(info.get("ports", ()))
            raise SerialException(f"{name} shares no {self._side} port (it shares {shared})")
        now = time.monotonic()
        self._origin = now - (now - sent) / 2 - float(info["time"])
        """`time.monotonic()` at the car's clock zero, as seen here: the car's times of
        its bytes plus this are this machine's (a recording here is timed at the car)."""
        self._said_at = float(info["time"])

    def _declare(self) -> None:
        import zenoh

        session, keys = self._session, self._keys
        self._declared: list[Any] = [
            session.declare_subscriber(keys.bytes(self._side), self._on_bytes),
            session.declare_subscriber(keys.events, self._on_event),
            session.liveliness().declare_subscriber(keys.presence, self._on_presence, history=True),
            session.liveliness().declare_token(keys.driver(self._client)),
        ]
        self._writer = session.declare_querier(
            keys.write(self._side),
            target=zenoh.QueryTarget.ALL,  # the car's host's queryable too, whatever is nearer
            consolidation=zenoh.ConsolidationMode.NONE,
            timeout=WRITE_TIMEOUT,
        )
        self._beating = threading.Event()
        self._datagrams = BeatSender(self._remote.connect)  # here: a name it resolves
        # holds up no heartbeat
        self._beats = threading.Thread(target=self._beat, name="zenoh beat", daemon=True)
        self._beats.start()

    # ------------------------------------------------------------ what comes

    def _on_bytes(self, sample: zenoh.Sample) -> None:
        stamped = None if sample.attachment is None else unstamp(sample.attachment.to_bytes())
        if stamped is None or not concrete(sample.key_expr):
            return
        at, direction, stamp = stamped
        if direction not in RECEIVED_DIRECTIONS or at < self._heard:  # a replay's are older
            return
        if not self._trust.sample(sample, stamp):
            return  # not the car's host's
        data = sample.payload.to_bytes()
        self._host_heard = time.monotonic()
        if not self._joined:  # the APP port's stream is joined at a record's start
            start = data.find(b"{")
            if start < 0:
                return
            data, self._joined = data[start:], True
        with self._ready:
            self._rx += data
            self._rx_times.append([at, len(data)])
            self._heard = max(self._heard, at)
            self._ready.notify_all()

    def _on_event(self, sample: zenoh.Sample) -> None:
        event = json_object(sample.payload.to_bytes())
        if event is None or not concrete(sample.key_expr):
            return  # not the car's host's JSON, or nobody's word (a wildcard's)
        at = event.get("at")
        if not isinstance(at, int | float) or at < self._said_at - REPLAY:
            return  # a replay of what the car's host said before
        if not self._trust.sample(sample):
            return  # not the car's host's
        self._said_at = max(self._said_at, at)
        self._host_heard = time.monotonic()
        if event.get("t") == "dropped" and event.get("client") == self._client:
            self._lose(escaped(str(event.get("why"))[:200]))
        elif event.get("t") in ("stopped", "unstopped"):
            stopped = event["t"] == "stopped"
            with self._ready:
                said = str(event.get("text", "")).removeprefix("stopped: ")
                self._far_stops.append((escaped(said[:200]), stopped))
                self.host_stopped_car = stopped
        elif event.get("t") == "closed":
            self._host_closed = event.get("stopped") is True
            self._closed_at = time.monotonic()
            self._closing.set()
        elif event.get("t") == "link" and event.get("port") == self._side:
            said = escaped(str(event.get("text", ""))[:200])
            self.car_link_down = None if event.get("up") else f"{LINK_DOWN} ({said})"
        elif event.get("t") == "info":  # each second: a link event missed in opening
            self._links_said(event.get("links"))

    def _links_said(self, links: object) -> None:
        """The car's host's info on its link to this port (a link event's words stay)."""
        up = links.get(self._side) if isinstance(links, dict) else None
        if isinstance(up, bool):
            self.car_link_down = None if up else (self.car_link_down or LINK_DOWN)

    def _on_presence(self, sample: zenoh.Sample) -> None:
        import zenoh

        if sample.kind != zenoh.SampleKind.DELETE or not concrete(sample.key_expr):
            return
        name = self._remote.name
        said = self._closing.wait(CLOSING)  # the share says why it goes, before it goes
        if said and time.monotonic() - self._closed_at <= 2 * CLOSING:  # and just before
            self.host_stopped_car = self._host_closed
            done = (
                "it stopped the car first"
                if self._host_closed
                else (
                    "its stop was NOT delivered (its link to the car was down): the car may "
                    "keep its last command"
                )
            )
            self._lose(f"the car's host ended its share of {name}: {done}")
            return
        self._lose(
            f"the car's host is gone (appmode share of {name} was killed, or its machine "
            "or network is down): the car keeps its last command"
        )

    def _lose(self, why: str) -> None:
        with self._ready:
            self._lost = why
            self._ready.notify_all()

    def _beat(self) -> None:
        try:
            self._beat_until_lost(self._keys.alive, self._datagrams)
        finally:
            self._datagrams.close()

    def _beat_until_lost(self, alive: str, datagrams: BeatSender) -> None:
        while not self._beating.wait(BEAT):
            if time.monotonic() - self._host_heard > SILENT:
                self._lose(
                    f"the car's host has not been heard for {SILENT:g} s (the network between "
                    "is cut?): it stops the car when this client falls silent to it"
                )
                return
            proof = self._prover.words("alive", self._client)
            datagrams.send(f"{self._remote.name} {self._client}{proof}")  # a bare one too:
            # while the lease's secret is on its way, TCP under loss may hold Zenoh's back
            try:
                self._session.put(alive, self._client + proof)
            except Exception:  # a session closing under it: the port is closing too
                return

    # ------------------------------------------------------------ pyserial

    @property
    def clock_origin(self) -> float:
        return self._origin

    @property
    def heard_until(self) -> tuple[float, bool]:
        with self._ready:
            if self._rx_times:
                return self._rx_times[0][0], False
            return max(self._heard, time.monotonic() - self._origin - 0.001), True

    @property
    def in_waiting(self) -> int:
        self._check()
        return len(self._rx)

    def read(self, size: int = 1) -> bytes:
        deadline = None if self._timeout is None else time.monotonic() + self._timeout
        with self._ready:
            while len(self._rx) < size and self._lost is None:
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    break
                self._ready.wait(left)
            if not self._rx:
                self._check()
            data = bytes(self._rx[:size])
            del self._rx[:size]
            self.read_runs = []
            left_over = len(data)
            while left_over:
                run = self._rx_times[0]
                taken = min(left_over, int(run[1]))
                self.read_runs.append((run[0], taken))
                run[1] -= taken
                left_over -= taken
                if not run[1]:
                    self._rx_times.popleft()
        return data

    def far_stops(self) -> list[tuple[str, bool]]:
        """The car's host's stops since the last look: (what it said, whether it went out)."""
        with self._ready:
            taken = list(self._far_stops)
            self._far_stops.clear()
        return taken

    def write(self, data: bytes) -> int:
        self._check()
        self.host_stopped_car = False  # what is written now may move the car again
        payload = serial.to_bytes(data)
        if self._remote.take and self._remote.name not in _TOOK:
            self._take()
        sent = time.monotonic()
        until = f"{sent - self._origin + WRITE_TIMEOUT:.3f}"  # the car's clock: not after
        proof = self._prover.words("write", self._client, until, payload)
        asked = f"{self._client} {until}{proof}"
        with far.acknowledging():  # the car's host is the stop authority while it waits
            said = self._trust.answer(
                self._writer.get(payload=payload, attachment=asked), asked, payload
            )
        self.latency = (time.monotonic() - sent) * 1000
        if said is None:
            why = f"the car's host did not answer within {WRITE_TIMEOUT:g} s"
            self._lose(why + self._trust.refusal())
            self._check()
        assert said is not None
        if "at" not in said:
            raise _write_error(said)
        self._granted(said)
        self.written_at = float(said["at"])
        return len(payload)

    def _granted(self, said: dict[str, Any]) -> None:
        """Keep the secret the car's host granted the lease with (`proof`)."""
        secret = said.get("secret")
        if isinstance(secret, str):
            self._prover.secret = secret

    def _take(self) -> None:
        """Take the driving over (`take=1`), once: the car's host stops the car first."""
        body = json.dumps({"take": True})
        asked = self._client
        replies = ask(self._session, self._keys.lease, asked, WRITE_TIMEOUT, body)
        said = self._trust.answer(replies, asked, body)
        if said is None or not said.get("granted"):
            why = "no answer" if said is None else escaped(str(said.get("refused"))[:200])
            raise SerialException(f"cannot take the driving of {self._remote.name}: {why}")
        self._granted(said)
        _TOOK.add(self._remote.name)

    def _check(self) -> None:
        if self._lost is not None:
            raise SerialException(self._lost)

    def flush(self) -> None:
        """Every write is acknowledged when it returns."""

    def reset_input_buffer(self) -> None:
        with self._ready:
            self._rx.clear()
            self._rx_times.clear()

    def reset_output_buffer(self) -> None:
        """What was written has left."""

    def _reconfigure_port(self, force_update: bool = False) -> None:
        """The car's host sets its own port's rate."""

    @property
    def out_waiting(self) -> int:
        return 0

    def close(self) -> None:
        """Let go of the driving (the car's host stops the car if this client drove),
        then close the session."""
        if not self.is_open:
            return
        self.is_open = False
        self._beating.set()
        with contextlib.suppress(Exception):  # a session already gone has nothing to close
            body = json.dumps({"let_go": True})
            proof = self._prover.words("lease", self._client, body)
            list(
                self._session.get(
                    self._keys.lease, payload=body, attachment=self._client + proof, timeout=0.5
                )
            )
            for declared in self._declared:
                declared.undeclare()
            close_session(self._session)


def _write_error(said: dict[str, Any]) -> SerialException:
    """What the car's host's refusal of a write means: another client drives (the link
    stays up), or the car's link is down at its host."""
    if "refused" in said:
        return WriteRefused(str(said["refused"]))
    return SerialException(str(said.get("down", "the car's host did not take the bytes")))


def zenoh_module_or_serial_error() -> None:
    try:
        zenoh_module()
    except AppmodeError as exc:
        raise SerialException(str(exc)) from None
