"""Who drives a shared car, as a state machine with no I/O. One client at a time holds
the lease; its heartbeats renew it. A lease that lapses (LAPSE without a heartbeat: the
driver's process killed, its machine asleep, the network cut) is the car's host's to
act on: it stops the car. A client that writes while nobody drives becomes the driver;
while another's lease is live it drives only after taking over (`take`), which the
other hears of. A client whose lease was taken from it (it lapsed, another took over,
a fleet stop) drives no more: its writes are refused, as a frozen process's that wakes
up; a client's every link is a new id, so it drives again once it has reconnected.
What the driver sends after its grant proves itself (`proof`): a key holder who uses
the driver's id neither renews its lease nor drives under it."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from appmode.net.proof import Proof, new_secret

REVOKED = 256
"""Revoked clients remembered at most (the oldest forgotten)."""
LAPSE = 0.3
"""Seconds without a heartbeat after which a driver's lease has lapsed (a driver beats
every 0.05 s): the car is stopped within 0.5 s of its last sign of life."""
FIRST_PROOF = 2.5
"""Seconds after its grant in which a driver's heartbeats renew its lease unproven: its
secret is on its way to it, in the reply to its write (which it waits for 2 s at most,
`remote_port.WRITE_TIMEOUT`: TCP resending a lost packet over a slow link). Its first
proven message, or the end of this, ends that."""


@dataclass(frozen=True, slots=True)
class Driver:
    """The client that drives: its id, its machine's name (for people), since when."""

    client: str
    machine: str
    since: float
    secret: str = field(default_factory=new_secret, repr=False)
    """Given to the driver alone (in its grant's reply): its messages' proofs are under it."""


@dataclass(frozen=True, slots=True)
class Granted:
    """The client drives; `took_from` is the driver it took over from, if any."""

    took_from: Driver | None = None


@dataclass(frozen=True, slots=True)
class Refused:
    """Another client drives, its lease live."""

    driver: Driver

    def why(self, car: str, now: float) -> str:
        return (
            f"{car} is driven from {self.driver.machine} (for {now - self.driver.since:.0f} s): "
            "watch it, or take the driving over with take=1 in the URL"
        )


@dataclass(frozen=True, slots=True)
class Revoked:
    """This client's lease was taken from it: it drives no more (until it reconnects)."""

    def why(self, car: str) -> str:
        return (
            f"this client's lease on {car} was revoked (it went silent, or was stopped or "
            "taken over): it drives no more; reconnect to drive again"
        )


@dataclass(frozen=True, slots=True)
class Unproven:
    """A message under the driver's id without the driver's proof: another's."""

    def why(self, car: str) -> str:
        return (
            f"not the driver's: this message is under the id of {car}'s driver without its "
            "proof (another key holder's?)"
        )


class Lease:
    """The car's one driver, and when it was last heard."""

    def __init__(self) -> None:
        self.driver: Driver | None = None
        self._heard = 0.0
        self._revoked: deque[str] = deque(maxlen=REVOKED)
        self._counts: dict[str, int] = {}
        """The driver's last proven count of each kind of message (none yet: {})."""

    def proves(self, client: str, kind: str, proof: Proof | None, *parts: str | bytes) -> bool:
        """Whether `client` drives and `proof` is its, over `kind` and `parts`, with a
        count past its last of that kind (a replay is no proof): the count is taken."""
        driver = self.driver
        if driver is None or driver.client != client or proof is None:
            return False
        if proof.count <= self._counts.get(kind, 0) or not proof.holds(
            driver.secret, kind, client, *parts
        ):
            return False
        self._counts[kind] = proof.count
        return True

    def ask(
        self, client: str, machine: str, now: float, take: bool = False, proven: bool = False
    ) -> Granted | Refused | Revoked | Unproven:
        """`client` asks to drive (`take`: even though another does); the driver's own
        asking is `proven` (`proves`), or another's under its id."""
        if client in self._revoked:
            return Revoked()
        driver = self.driver
        if driver is not None and driver.client == client:
            if not proven:
                return Unproven()
            self._heard = now
            return Granted()
        if driver is not None and not self.lapsed_at(now) and not take:
            return Refused(driver)
        took = driver if driver is not None and not self.lapsed_at(now) else None
        if driver is not None:
            self._revoked.append(driver.client)  # taken over, or lapsed
        self.driver, self._heard, self._counts = Driver(client, machine, now), now, {}
        return Granted(took)

    def beat(self, client: str, now: float, proof: Proof | None) -> None:
        """A heartbeat: the driver's, proven (or before its secret can have reached it,
        `FIRST_PROOF`), renews its lease; others are watching."""
        driver = self.driver
        if self.proves(client, "alive", proof) or (
            driver is not None
            and driver.client == client
            and not self._counts
            and now - driver.since <= FIRST_PROOF
        ):
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
        """`client` ends its lease (it closed, proven, or its Zenoh session ended): the
        driver it was, or None."""
        if self.driver is None or self.driver.client != client:
            return None
        driver, self.driver = self.driver, None
        return driver
