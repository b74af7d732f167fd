"""The key expressions of a shared car, `appmode/NAME/…`, one table: what the car's host
publishes and answers, and what a client sends it."""

from __future__ import annotations

from dataclasses import dataclass

ROOT = "appmode"
USER = "appmode"
"""A key holder's user name in Zenoh's user-password authentication (the key is its
password): it asks, watches and drives (`roles`)."""
HOST_USER = "appmode-host"
"""A car's host's user name (the room's host key is its password): it speaks for cars."""


@dataclass(frozen=True, slots=True)
class Keys:
    """The keys of the car called `name`."""

    name: str

    def _key(self, *parts: str) -> str:
        return "/".join((ROOT, self.name, *parts))

    def bytes(self, port: str) -> str:
        """Every byte `port` (`app`, `uart2`) carried, both ways, timed at the car."""
        return self._key(port, "bytes")

    def write(self, port: str) -> str:
        """Where the driver's bytes for `port` go (a query: the reply says when they left)."""
        return self._key(port, "write")

    @property
    def lease(self) -> str:
        """Ask to drive, take over, or let go (a query)."""
        return self._key("lease")

    @property
    def alive(self) -> str:
        """The driver's heartbeats."""
        return self._key("alive")

    @property
    def events(self) -> str:
        """What the car's host says: who drives, a lease that lapsed, a stop it sent."""
        return self._key("events")

    @property
    def info(self) -> str:
        """The car as `fleet` shows it (a query)."""
        return self._key("info")

    @property
    def stop(self) -> str:
        """Stop the car now (a query: the reply says whether it took)."""
        return self._key("stop")

    @property
    def records(self) -> str:
        """The APP port's records, decoded (JSON)."""
        return self._key("records")

    @property
    def presence(self) -> str:
        """The car's host's liveliness token: the car is shared."""
        return self._key("presence")

    def host(self, zid: str) -> str:
        """A host's liveliness token for the car: two of them, two cars of one name."""
        return self._key("host", zid)

    def driver(self, client: str) -> str:
        """A driver's liveliness token: its Zenoh session is alive."""
        return self._key("driver", client)


ANY_INFO = f"{ROOT}/*/info"
ANY_STOP = f"{ROOT}/*/stop"


def name_of(key: str) -> str:
    """The car's name in one of its keys ("" when it is none of a car's)."""
    parts = key.split("/")
    return parts[1] if len(parts) > 2 and parts[0] == ROOT else ""


def concrete(key: object) -> bool:
    """Whether a sample's, reply's or token's key names one thing: one published on a
    wildcard (`**`, `appmode/*/events`, which Zenoh delivers to every subscriber it
    intersects) is nobody's word."""
    return "*" not in str(key)
