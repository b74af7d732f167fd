"""A car shared on Zenoh from the machine it is wired to (`appmode share`): its ports'
bytes, both ways, timed at the car; its records decoded; who drives; and the stop
authority. A remote client drives by sending bytes (`names.Keys.write`), which the car's
host writes to the car while the client holds the lease (`lease.Lease`); when the lease
lapses, when the driver's Zenoh session ends, and when the share ends, the car's host
sends the port's stop itself — no remote host is trusted to."""

from __future__ import annotations

import json
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from appmode.errors import AppmodeError
from appmode.host.app.state import HostState
from appmode.host.app.stop_check import SETTLE
from appmode.host.events import LinkStatus
from appmode.host.kinds import AnyHost, open_hosts
from appmode.host.link import Cut, LinkLost
from appmode.net.asked import NOT_ASKED, asked_by, json_of, proof_of, text_of, write_refusal
from appmode.net.hosts import claim
from appmode.net.last_records import LastRecords
from appmode.net.lease import Driver, Granted, Lease, Refused, Revoked, Unproven
from appmode.net.names import ANY_STOP, Keys, concrete
from appmode.net.stamps import stamp
from appmode.protocol import app
from appmode.protocol.reader import SENT_DIRECTIONS
from appmode.protocol.render import to_json
from appmode.text import escaped, shortened

if TYPE_CHECKING:
    import zenoh

    from appmode.net.signature import Signer
    from appmode.ports.choice import BoardChoice

TICK = 0.02
"""Seconds between the share's looks at the car and at the lease."""
INFO_EVERY = 1.0
"""Seconds between two `info` samples published while nothing changes."""
Log = Callable[[str], None]


@dataclass
class Port:
    """One of the car's ports as the share holds it."""

    name: str
    """`app` or `uart2`."""
    host: AnyHost


class Share:
    """The car of `choice`'s ports shared as `name` on `session` until `close`, its
    replies and samples signed by `signer`."""

    def __init__(
        self, session: zenoh.Session, name: str, choice: BoardChoice, log: Log, signer: Signer
    ) -> None:
        self.session = session
        self.signer = signer
        self.keys = Keys(name)
        self.choice = choice
        self.log = log
        self.lease = Lease()
        self._lock = threading.RLock()  # the lease and the writes, from Zenoh's threads
        self._origin = time.monotonic()
        self.ports: dict[str, Port] = {}
        self._written: dict[str, float | None] = {}
        """When each port's last bytes were written (the tap's time of them)."""
        self._used: set[str] = set()
        """The ports clients have written to: the ones a stop is for (a zero frame on an
        unused control port would take the motion over from the APP port, §8.3)."""
        self._last = LastRecords()
        self._stops = 0
        """Stops sent so far: a write lets its rest go only while none came since it began."""
        self._host_token: Any = None
        self._events: Any = None
        """The events' publisher, once declared (after the stop at the start)."""

        self._closed = threading.Event()
        for port, host in open_hosts(choice, self._tap).items():
            host.stop_on_close = not self.ports  # the first port's, until another is used
            self.ports[port] = Port(port, host)
        try:
            self._host_token = claim(session, self.keys)
            self._stop_at_start()
            self._declare()
        except BaseException:
            self.close()
            raise

    def now(self) -> float:
        """The car's time: seconds since the share began (every sample carries it)."""
        return time.monotonic() - self._origin

    # ------------------------------------------------------------ Zenoh

    def _declare(self) -> None:
        keys, session = self.keys, self.session
        self._declared: list[Any] = [
            session.declare_queryable(keys.lease, self._on_lease),
            session.declare_queryable(keys.info, self._on_info),
            session.declare_queryable(keys.stop, self._on_stop),
            session.declare_subscriber(keys.alive, self._on_alive),
            session.liveliness().declare_subscriber(keys.driver("*"), self._on_driver),
            session.liveliness().declare_token(keys.presence),
        ]
        for port in self.ports:
            self._declared.append(session.declare_queryable(keys.write(port), self._writer(port)))
        self._publishers = {
            port: session.declare_publisher(keys.bytes(port)) for port in self.ports
        }
        self._records = session.declare_publisher(keys.records)
        self._events = session.declare_publisher(keys.events)

    def _tap(self, port: str) -> Callable[[str, float, bytes], None]:
        """Each byte the car's port carries, published with the car's time of it."""

        def tap(direction: str, at: float, data: bytes) -> None:
            link = self.ports[port].host if port in self.ports else None
            publisher = getattr(self, "_publishers", {}).get(port)
            if link is None or publisher is None or self._closed.is_set():
                return
            when = at + link.origin - self._origin
            if direction in SENT_DIRECTIONS:
                self._written[port] = when
            self.signer.put(publisher, self.keys.bytes(port), data, stamp(when, direction))

        return tap

    def _writer(self, port: str) -> Callable[[zenoh.Query], None]:
        key = self.keys.write(port)

        def answer(query: zenoh.Query, **said: object) -> None:
            self.signer.reply(query, key, json.dumps(said))

        def on_write(query: zenoh.Query) -> None:
            data = b"" if query.payload is None else query.payload.to_bytes()
            words = asked_by(query, key)
            refused = write_refusal(words, data, self.now())
            if refused == NOT_ASKED:  # no client's: nobody's answer to sign
                query.reply_err(NOT_ASKED)
                return
            with self._lock:
                if refused is None and words is not None:
                    proof = proof_of(words, 2)
                    proven = self.lease.proves(words[0], "write", proof, words[1], data)
                    refused = self._may_drive(words[0], take=False, proven=proven)
                if refused is not None:
                    answer(query, refused=refused)
                    return
                secret = self._secret()
                host = self.ports[port].host
                self._used.add(port)
                host.stop_on_close = True
                self._written[port] = None
                stops = self._stops
            try:  # outside the lock: a stop pre-empts it, and none is sent after one
                host.send(data, still=lambda: self._stops == stops)
            except Cut as exc:
                answer(query, refused=f"the car's host stopped the car: {exc}")
                return
            except LinkLost as exc:
                answer(query, down=f"the car's {port} link is down at its host ({exc})")
                return
            except AppmodeError:
                pass  # written: only the share's own recording failed
            written = self._written.get(port)
            at = self.now() if written is None else written
            answer(query, at=at, driving=True, **secret)

        return on_write

    def _may_drive(self, client: str, take: bool, proven: bool) -> str | None:
        """None when `client` may drive (the lease granted it), else why not."""
        machine = client.rsplit("-", 2)[0]
        answer = self.lease.ask(client, machine, self.now(), take, proven)
        if isinstance(answer, Unproven | Revoked):
            return answer.why(self.keys.name)
        if isinstance(answer, Refused):
            return answer.why(self.keys.name, self.now())
        assert isinstance(answer, Granted)
        if answer.took_from is not None:
            self._stop_car(f"{machine} took the driving over from {answer.took_from.machine}")
            self._dropped(
                answer.took_from,
                f"{machine} took the driving over: this client watches (take it back with take=1)",
            )
        return None

    def _on_lease(self, query: zenoh.Query) -> None:
        words = asked_by(query, self.keys.lease)
        asked = json_of(query)
        if words is None or asked is None:
            query.reply_err(NOT_ASKED)
            return
        client, body = words[0], text_of(query.payload) or ""
        with self._lock:
            proven = self.lease.proves(client, "lease", proof_of(words, 1), body)
            if asked.get("let_go"):
                driver = self.lease.let_go(client) if proven else None
                if driver is not None:
                    self._stop_car(f"the driver on {driver.machine} let go of the driving")
                self.signer.reply(query, self.keys.lease, json.dumps({"granted": False}))
                return
            refused = self._may_drive(client, take=bool(asked.get("take")), proven=proven)
            secret = self._secret()
        said = {"granted": True, **secret} if refused is None else {"refused": refused}
        self.signer.reply(query, self.keys.lease, json.dumps(said))

    def _secret(self) -> dict[str, str]:
        """The driver's secret, for the reply to its own granted query (only it gets it)."""
        driver = self.lease.driver
        return {} if driver is None else {"secret": driver.secret}

    def _on_alive(self, sample: zenoh.Sample) -> None:
        if str(sample.key_expr) == self.keys.alive:
            self.beat((text_of(sample.payload) or "").split(" "))

    def beat(self, words: list[str]) -> None:
        """A heartbeat's words, `CLIENT COUNT MAC` (on Zenoh, or a datagram: `beats`)."""
        if words and words[0]:
            with self._lock:
                self.lease.beat(words[0], self.now(), proof_of(words, 1))

    def _on_driver(self, sample: zenoh.Sample) -> None:
        """A client's Zenoh session ended (its liveliness token went): if it drove, the
        car stops now, without waiting for the lease to lapse."""
        import zenoh

        if sample.kind != zenoh.SampleKind.DELETE or not concrete(sample.key_expr):
            return
        client = str(sample.key_expr).rsplit("/", 1)[1]
        with self._lock:
            driver = self.lease.let_go(client)
            if driver is not None:
                self._stop_car(f"the driver on {driver.machine} left (its session ended)")

    def _on_info(self, query: zenoh.Query) -> None:
        self.signer.reply(query, self.keys.info, json.dumps(self.info()))

    def _on_stop(self, query: zenoh.Query) -> None:
        """`fleet stop`: stop the car and say whether it took (on its A records, when
        they come), in a thread of its own: a confirmation takes up to SETTLE s."""
        if str(query.key_expr) not in (self.keys.stop, ANY_STOP):
            query.reply_err(NOT_ASKED)  # `get appmode/**` is no fleet stop
            return
        asker = (text_of(query.attachment) or "").split(" ")[0]  # then the client's token
        who = shortened(escaped(asker)) or "a client"

        def stop() -> None:
            with self._lock:
                driver = self.lease.driver
                if driver is not None:
                    self.lease.revoke(driver.client)
                sent = self._stop_car(f"stopped by {who} (fleet stop)")
                if driver is not None:
                    self._dropped(driver, f"{who} stopped every car (fleet stop)")
            confirmed = self._confirmed() if sent else None
            reply = {"name": self.keys.name, "sent": sent, "confirmed": confirmed}
            self.signer.reply(query, self.keys.stop, json.dumps(reply))

        threading.Thread(target=stop, name="fleet stop", daemon=True).start()

    # ------------------------------------------------------------ the stop authority

    def _stop_car(self, why: str, say: bool = True) -> bool:
        """Send the stop of every port a client used (the APP port's when none was):
        whether each went out (a port whose link is down cannot be stopped: said)."""
        self._stops += 1  # a write under way gives way, and none begun before goes out
        ports = [port for name, port in self.ports.items() if name in self._stopping()]
        sent = all(port.host.send_stop() is not None for port in ports)
        text = f"stopped: {why}" if sent else f"{why}: the stop was NOT delivered (link down)"
        if say or not sent:
            self.log(text)
        self._event("stopped" if sent else "unstopped", text=text)
        return sent

    def _stopping(self) -> set[str]:
        """The ports a stop goes to: those written to, or in motion, else the first."""
        moving = {name for name, port in self.ports.items() if port.host.in_force_text()}
        return (self._used | moving) or {next(iter(self.ports))}

    def _telemetry(self) -> HostState | None:
        """The state of the APP records one of the car's ports carries, if one does."""
        return next(
            (p.host.telemetry for p in self.ports.values() if p.host.telemetry is not None), None
        )

    def _confirmed(self) -> bool | None:
        """Whether an A record of the APP port showed the car at rest within SETTLE s of
        the stop, as the local host judges it (None: it sends none here)."""
        state = self._telemetry()
        if state is None:
            return None
        end = time.monotonic() + SETTLE
        self._last.velocity = None
        while time.monotonic() < end:
            time.sleep(TICK)
            if self._last.moving(state.layout) is False:
                return True
        return None if self._last.velocity is None else False

    def _dropped(self, driver: Driver, why: str) -> None:
        """Tell `driver` it drives no more, and why (its port is lost: it says so)."""
        self._event("dropped", client=driver.client, why=why)

    def _event(self, kind: str, **fields: object) -> None:
        if self._events is not None and not self._closed.is_set():
            said = json.dumps({"t": kind, "at": round(self.now(), 3), **fields})
            self.signer.put(self._events, self.keys.events, said)

    def info(self) -> dict[str, object]:
        """The car as `fleet` shows it."""
        driver = self.lease.driver
        links = {name: port.host.connected for name, port in self.ports.items()}
        motions = [port.host.in_force_text() for port in self.ports.values()]
        return {
            "name": self.keys.name,
            "profile": self.choice.profile.name,
            "simulated": all(port.host.target.simulated for port in self.ports.values()),
            "ports": list(self.ports),
            "links": links,
            "machine": socket.gethostname(),
            "driver": None if driver is None else _driver(driver),
            "battery": self._last.battery,
            "in_force": next(filter(None, motions), None),
            "moving": any(motions) or self._records_moving() is True,
            "records_moving": self._records_moving(),
            "params": self._params(),
            "time": round(self.now(), 3),
        }

    def _params(self) -> dict[str, Any] | None:
        """The parameters as the car last sent them (its C record), when it has."""
        state = self._telemetry()
        if state is None or state.params is None:
            return None
        body = to_json(state.params, state.layout)
        return {k: v for k, v in body.items() if k not in ("kind", "raw")}

    # ------------------------------------------------------------ running

    def run(self, ended: Callable[[], bool]) -> None:
        """Read the car's ports, publish what they bring, watch the lease, until `ended()`
        (or `close`)."""
        next_info = 0.0
        while not ended() and not self._closed.is_set():
            for port in self.ports.values():
                for event in port.host.poll(TICK / len(self.ports)):
                    self._seen(port, event)
            with self._lock:
                lapsed = self.lease.lapsed(self.now())
                if lapsed is not None:
                    self._stop_car(f"the driver on {lapsed.machine} went silent")
                    self._dropped(
                        lapsed,
                        "the car's host stopped the car: this client's heartbeats stopped "
                        "reaching it",
                    )
            if time.monotonic() >= next_info:
                next_info = time.monotonic() + INFO_EVERY
                self._event("info", **self.info())

    def _stop_at_start(self) -> None:
        """A share that starts, or restarts (the car its last host left moving), stops the
        car before any client can reach it — `Z` on the APP port, which takes nothing
        over — and judges the stop on the car's A records; where they still show it
        moving after SETTLE s, a frame took the motion over before this share began
        (§8.3): the control port's zero frame, judged again. Says what they showed."""
        first = self._stopping()  # the APP port, which a stop takes nothing over on
        if not self._stop_car("the car's host started: the car stops first", say=False):
            return
        state = self._telemetry()
        if state is None:
            self.log("the car stopped first (its host started): no records here confirm it")
            return
        at_rest = self._at_rest(state)
        others = [name for name in self.ports if name not in first]
        if at_rest is False and others:
            self._used.update(others)
            self._stop_car("the car's records show it moving: the control port drives it")
            at_rest = self._at_rest(state)
        self.log(
            "the car stopped first (its host started): "
            + {
                True: "confirmed on its records (at rest)",
                False: "its records show it MOVING: stop it by hand",
                None: "no record came to confirm it",
            }[at_rest]
        )

    def _at_rest(self, state: HostState) -> bool | None:
        """Read the car's ports for up to SETTLE s: True at the first A record at rest,
        False when the last showed it moving, None when none came."""
        end, moving = time.monotonic() + SETTLE, None
        while time.monotonic() < end:
            for port in self.ports.values():
                for event in port.host.poll(TICK / len(self.ports)):
                    seen = self._last.saw(event, self.now(), state.layout)
                    if seen is False:
                        return True
                    moving = moving or seen
        return None if moving is None else False

    def _records_moving(self) -> bool | None:
        """Whether the car's last A record (of the last second) shows it moving; None:
        none came."""
        state = self._telemetry()
        return None if state is None else self._last.moving(state.layout, self.now())

    def _seen(self, port: Port, event: object) -> None:
        if isinstance(event, LinkStatus):
            self.log(f"{port.name}: {event.text}")
            self._event("link", port=port.name, up=event.up, text=event.text)
            return
        state = port.host.telemetry
        if state is not None:
            self._last.saw(event, self.now(), state.layout)
        if isinstance(event, app.RECORDS) and state is not None:
            body = to_json(event, state.layout)
            said = json.dumps({"t": round(self.now(), 3), **body})
            self.signer.put(self._records, self.keys.records, said)

    def close(self) -> None:
        """Stop sharing: the car's stop last on every port (its hosts close), then the
        Zenoh declarations."""
        self._closed.set()
        self._stops += 1
        stopping = self._stopping()
        delivered = True
        for name, port in self.ports.items():
            port.host.stop_on_close = name in stopping
            delivered &= port.host.close() is not None or name not in stopping
        if self._events is not None:  # before the token goes: clients hear why it went
            said = {"t": "closed", "at": round(self.now(), 3), "stopped": delivered}
            self.signer.put(self._events, self.keys.events, json.dumps(said))
        for declared in [*getattr(self, "_declared", []), self._host_token]:
            if declared is not None:
                declared.undeclare()


def _driver(driver: Driver) -> dict[str, object]:
    return {"machine": driver.machine, "client": driver.client, "since": round(driver.since, 1)}
