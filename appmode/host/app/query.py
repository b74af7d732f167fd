"""Parameter reads and verified sets as a state machine, with no I/O.

A ParamQuery sends `{Q:P}` (after `{n:v}` for a set) and waits for C records. The
protocol has no checksum, so a lost or doubled digit can still make a well-formed C
record — and the same wrong one often: `10000` losing any of its four zeros reads
`1000`. So the C records of a query, each asked for separately, are votes: a value is
reported when it has AGREE votes and leads every other value by AGREE — or, once the
link has shown noise (two C records that differ, or, once the link has carried a
record, a garbled record of any kind during the query or in the DEGRADED_WINDOW before
it), by NOISY_LEAD (docs/protocol.md §3.3).
A set is done when the agreed values show it; records that still show the value read
before it stop counting once one shows the new value. On a timeout the request is sent
again; after `tries × agree` requests (NOISY_LEAD for agree on a noisy link; each
garbled answer gives its request back, up to as many again) the query ends in
QueryFailed.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from appmode.host.outcomes import AGREE, TRIES, QueryFailed
from appmode.protocol import app, param_values
from appmode.protocol.param_values import Specs

TIMEOUT = 0.5
NOISY_LEAD = 4
"""The lead a value needs over every other once the link has shown noise: a wrong value
that a noisy link makes 5 % of the time then wins before the true one with odds of
about (0.05 / 0.8)^4, 1 in 65,000 queries (docs/protocol.md §3.3)."""


@dataclass(frozen=True, slots=True)
class QueryDone:
    values: tuple[int, ...]
    text: str


Outcome = QueryDone | QueryFailed


MISMATCHES = 3
"""Rounds of agreeing C records showing another value after which a set has failed: the
set frame was sent again before each later round, so the board decided, not the link
(a frame lost on its way leaves the board's value as it was: with one re-sent frame, a
link that damages one frame in 20 made a board that took a damaged set look as if it
had refused, once in 20 such sets; with two, once in 400). On a link that has shown
noise, NOISY_MISMATCHES: its frames are lost far more often than one in 20 (the suite's
moderate faults lost three in a row under load)."""
NOISY_MISMATCHES = 5


class ParamQuery:
    """Read the parameters, or set one and verify it by reading back."""

    def __init__(
        self,
        change: tuple[int, int] | None = None,
        timeout: float = TIMEOUT,
        tries: int = TRIES,
        where: str = "the board",
        agree: int = AGREE,
        specs: Specs = param_values.SHEET,
    ) -> None:
        if change is not None:
            param_values.check(specs, *change)
        self.specs = specs
        """The parameters' table (the profile's): their names and ranges."""
        self.change = change
        self.timeout = timeout
        self.tries = tries
        self.where = where
        self.agree = agree
        self.sent = 0
        self.deadline = 0.0
        self._votes: Counter[tuple[int, ...]] = Counter()
        self._noisy = False
        self._mismatch: int | None = None
        self._mismatches = 0
        self._replies = 0
        """C records received, garbled ones too: requests are answered in order."""
        self._garbled = 0
        """C records received garbled: answers, so the board is there; each gives its
        request back to `limit`."""
        self._stale = 0
        """C records still to come in answer to requests sent before the set was sent
        again: they show the board before it, and are not votes."""
        self.known: tuple[int, ...] | None = None
        """The parameters the host read last, before this query (set by HostState)."""

    @property
    def limit(self) -> int:
        """Requests at most: `tries` times the votes a value needs, plus one for each
        garbled answer up to as many again (a noisy link's answers are no silence: one
        set in about 400 under the suite's moderate faults took all of the first 20)."""
        base = self.tries * (NOISY_LEAD if self._noisy else self.agree)
        return base + min(self._garbled, base)

    def _request(self, now: float, with_change: bool) -> bytes:
        self.sent += 1
        self.deadline = now + self.timeout
        read = app.encode(app.ReadParams())
        if self.change is None or not with_change:
            return read
        return app.set_frame(*self.change) + read

    def start(self, now: float) -> bytes:
        """The bytes to send first."""
        return self._request(now, with_change=True)

    def on_params(self, values: tuple[int, ...], now: float) -> tuple[bytes, Outcome | None]:
        """A C record arrived: (bytes to send, outcome or None)."""
        self._replies += 1
        if self._stale:
            self._stale -= 1
            return b"", None
        votes = self._votes
        if self.change is not None and self.known is not None:
            index, value = self.change
            if values[index] == value != self.known[index]:  # the set has taken:
                for before in [v for v in votes if v[index] == self.known[index]]:
                    del votes[before]  # the records from before it are history
        votes[values] += 1
        self._noisy = self._noisy or len(votes) > 1
        lead = votes[values] - max((n for v, n in votes.items() if v != values), default=0)
        if votes[values] < self.agree or lead < (NOISY_LEAD if self._noisy else self.agree):
            if self.sent >= self.limit:
                return self._retry(now)
            return self._request(now, with_change=False), None  # ask again to confirm
        if self.change is None:
            return b"", QueryDone(values, "parameters read")
        index, value = self.change
        if values[index] == value:
            spec = self.specs[index]
            shown = param_values.to_user(spec, value)
            return b"", QueryDone(values, f"{spec.name} = {shown} (verified)")
        same = self._mismatch == values[index]
        self._mismatch = values[index]
        self._mismatches = self._mismatches + 1 if same else 1
        self._votes.clear()  # the set is sent again: the board may change
        rounds = NOISY_MISMATCHES if self._noisy else MISMATCHES
        if self._mismatches >= rounds:  # the board has decided: say what it did
            return b"", self._refused(index, value)
        self._stale = max(0, self.sent - self._replies)  # reads already on their way
        return self._retry(now)

    def _refused(self, index: int, value: int) -> QueryFailed:
        spec = self.specs[index]
        name = spec.name
        mismatch = self._mismatch
        held = "?" if mismatch is None else param_values.to_user(spec, mismatch)
        if self.known is None:
            what = f"{name} reads {held}"
        elif mismatch == self.known[index]:
            what = f"the board ignored it: {name} is still {held}"
        else:
            what = f"the board set {name} to {held} instead"
        return QueryFailed(
            f"set {name} = {param_values.to_user(spec, value)} was not taken: {what}"
        )

    def link_noisy(self) -> None:
        """The link has garbled a record (any record, not only this query's): its C
        records may be wrong in the same way, so a value needs NOISY_LEAD."""
        self._noisy = True

    def on_garbled(self, now: float) -> tuple[bytes, Outcome | None]:
        """A C record arrived garbled: the link is noisy; ask again at once rather than
        wait for the timeout."""
        self._replies += 1
        self._garbled += 1
        self._stale = max(0, self._stale - 1)
        self._noisy = True
        return self._retry(now)

    def on_time(self, now: float) -> tuple[bytes, Outcome | None]:
        """Call as time passes: a resend, a failure, or nothing yet."""
        if now < self.deadline:
            return b"", None
        return self._retry(now)

    def _retry(self, now: float) -> tuple[bytes, Outcome | None]:
        if self.sent < self.limit:
            return self._request(now, with_change=True), None
        if self.change is not None and self._mismatch is not None:
            return b"", self._refused(*self.change)
        return b"", QueryFailed(
            f"no parameters from {self.where}: sent {{Q:P}} {self.sent} times and no "
            f"{self.agree} C records that agree came back ({self.timeout:g} s each); "
            f"check the board is on, the port and baud rate (9600), and that no other "
            f"program is using the port"
        )
