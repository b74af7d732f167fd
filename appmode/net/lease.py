"""Who drives a shared car, as a state machine with no I/O. One client at a time holds
the lease; its heartbeats renew it. A lease that lapses (LAPSE without a heartbeat: the
driver's process killed, its machine asleep, the network cut) is the car's host's to
act on: it stops the car. A client that writes while nobody drives becomes the driver;
while another's lease is live it drives only after taking over (`take`), which the
other hears of. A client whose lease was taken from it (it lapsed, another took over,
a fleet stop) drives no more: its writes are refused, as a frozen process's that wakes
up; a client's every link is a new id, so it drives again once it has reconnected."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

REVOKED = 256
"""Revoked clients remembered at most (the oldest forgotten)."""
LAPSE = 0.3
"""Seconds without a heartbeat after which a driver's lease has lapsed (a driver beats
every 0.1 s): the car is stopped within 0.5 s of its last sign of life."""


@dataclass(frozen=True, slots=True)
class Driver:
    """The client that drives: its id, its machine's name (for people), since when."""

    client: str
    machine: str
    since: float


@dataclass(frozen=True, slots=True)
class Granted:
    """The client drives; `took_from` is the driver it took over from, if any."""

    took_from: Driver | None = None


@dataclass(frozen=True, slots=True)
class Refused:
    """Another client drives, its lease live."""

    driver: Driver


@dataclass(frozen=True, slots=True)
class Revoked:
    """This client's lease was taken from it: it drives no more (until it reconnects)."""


class Lease:
    """The car's one driver, and when it was last heard."""

    def __init__(self) -> None:
        self.driver: Driver | None = None
        self._heard = 0.0
        self._revoked: deque[str] = deque(maxlen=REVOKED)

    def ask(
        self, client: str, machine: str, now: float, take: bool = False
    ) -> Granted | Refused | Revoked:
        """`client` asks to drive (`take`: even though another does)."""
        if client in self._revoked:
            return Revoked()
        driver = self.driver
        if driver is not None and driver.client == client:
            self._heard = now
            return Granted()
        if driver is not None and not self.lapsed_at(now) and not take:
            return Refused(driver)
        took = driver if driver is not None and not self.lapsed_at(now) else None
        if driver is not None:
            self._revoked.append(driver.client)  # taken over, or lapsed
        self.driver, self._heard = Driver(client, machine, now), now
        return Granted(took)

    def beat(self, client: str, now: float) -> None:
        """A heartbeat: the driver's renews its lease (others are only watching)."""
        if self.driver is not None and self.driver.client == client:
            self._heard = now

    def lapsed_at(self, now: float) -> bool:
        return self.driver is not None and now - self._heard > LAPSE

    def lapsed(self, now: float) -> Driver | None:
        """The driver whose lease has just lapsed (it drives no more), or None."""
        if not self.lapsed_at(now):
            return None
        driver, self.driver = self.driver, None
        if driver is not None:
            self._revoked.append(driver.client)
        return driver

    def revoke(self, client: str) -> Driver | None:
        """Take the lease from `client` (a fleet stop): the driver it was, or None."""
        driver = self.let_go(client)
        if driver is not None:
            self._revoked.append(client)
        return driver

    def let_go(self, client: str) -> Driver | None:
        """`client` ends its lease (it closed, or its Zenoh session ended): the driver it
        was, or None."""
        if self.driver is None or self.driver.client != client:
            return None
        driver, self.driver = self.driver, None
        return driver
