"""The host side as a state machine, with no I/O: what the host knows of the board.

`HostState.feed(data, now)` decodes board bytes and keeps the last A, B and C records (and
the last seconds of A and B, for waveforms) and the link statistics; a view (console,
monitor) reads them.
"""

from __future__ import annotations

from collections import deque

from appmode.host.app.query import Outcome, ParamQuery
from appmode.host.events import BoardWarning
from appmode.host.outcomes import QueryFailed
from appmode.host.stats import LinkStats
from appmode.protocol import app, params, session_end
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.render import motion_text
from appmode.text import counted

TRACE_SECONDS = 10.0
"""How much of the telemetry the host keeps, for waveforms."""
OUTSIDE = 256
"""Bytes kept of what came outside records (`HostState.outside`)."""


Sample = app.Velocity | app.Attitude | app.OtherRecord
"""A record a trace keeps: A, or B (a profile's own B record is an OtherRecord)."""


class Trace:
    """The last TRACE_SECONDS of one kind of record, each with the time it came."""

    def __init__(self) -> None:
        self.points: deque[tuple[float, Sample]] = deque(maxlen=4096)

    def add(self, now: float, event: Sample) -> None:
        self.points.append((now, event))
        while self.points and self.points[0][0] < now - TRACE_SECONDS:
            self.points.popleft()

    def age(self, now: float) -> float | None:
        """Seconds since the last record, or None if none came."""
        return now - self.points[-1][0] if self.points else None


STILL_MOVING_AFTER = 1.0
"""Seconds after a stop by which the board's A records must show the car (almost) still."""
STILL = 20
"""The largest velocity component of a car taken as stopped (a decaying ramp, §13)."""
FOLLOW_AFTER = 1.0
"""Seconds after a drive letter by which the A records must show the car moving."""


class HostState:
    """Last records seen and link counters, fed with the board's bytes."""

    def __init__(self, layout: Layout = VELOCITY, frames_stop: bool = False) -> None:
        self.layout = layout
        """How the board's A records are laid out (§3.1, §13)."""
        self.frames_stop = frames_stop
        """Every frame sent stops the car (a minibalance board: its `{` steers, §13)."""
        self.decoder = self.layout.board_decoder()
        self.in_step = False
        """A record has come since the link opened: undecodable bytes are errors now."""
        self.outside = bytearray()
        """The first OUTSIDE bytes that were no record (a firmware's `##$` reply)."""
        self.stats = LinkStats()
        self.velocity: app.Velocity | None = None
        self.attitude: app.Attitude | None = None
        self.velocities = Trace()
        self.attitudes = Trace()
        self.params: app.ParamsRecord | None = None
        self.query: ParamQuery | None = None
        self._errors_at_start = 0
        self._outbox = bytearray()
        self.end = session_end.SessionEnd(layout.profile.speed_keys, frames_stop)
        """What the board was last sent: the letter it follows, the stop that ends it."""
        self.stopped_at: float | None = None
        """When the host last told the car to stop (Z or a page letter), while it has not
        told it to move since."""
        self._warned = False
        self.moving_since: float | None = None
        """When the host last sent a drive letter, while it has not stopped the car since."""
        self.letters_ignored = False
        """A drive letter was in force for FOLLOW_AFTER s and the car stood still: the
        control port (UART2, §8.3) drives it. The take-over lasts until the board is
        reset, so this holds until the link is lost."""

    def feed(self, data: bytes, now: float) -> list[app.BoardEvent | Outcome | BoardWarning]:
        """Decode board bytes; returns the events, the outcome of a query they end, and a
        warning if the car still moves well after a stop."""
        self.stats.bytes_in += len(data)
        events: list[app.BoardEvent | Outcome | BoardWarning] = []
        for event in self.decoder.feed(data):
            events.append(event)
            outcome = self._apply(event, now)
            if outcome is not None:
                events.append(outcome)
            if isinstance(event, app.Velocity):
                for warning in (self._disobeyed(event, now), self._ignored(event, now)):
                    if warning is not None:
                        events.append(warning)
        return events

    def sent(self, data: bytes, now: float) -> None:
        self.stats.bytes_out += len(data)
        for event in self.end.sent(data):
            if isinstance(event, app.Move):
                self.stopped_at = None
                self.moving_since = now
            elif isinstance(event, (app.Stop, app.SwitchPage)) or (
                self.frames_stop and event.raw.startswith(b"{")
            ):
                self.stopped_at, self._warned = now, False
                self.moving_since = None

    def stopped_far(self, now: float) -> None:
        """The far end (a shared car's host) stopped the car: as if this host sent Z."""
        list(self.end.sent(b"Z"))
        self.stopped_at, self._warned = now, False
        self.moving_since = None

    def _disobeyed(self, velocity: app.Velocity, now: float) -> BoardWarning | None:
        stopped = self.stopped_at
        if stopped is None or self._warned or now - stopped < STILL_MOVING_AFTER:
            return None
        if self.layout.speed(velocity.values) <= STILL:
            return None
        self._warned = True
        return BoardWarning(
            f"the car still moves {now - stopped:.1f} s after it was told to stop "
            f"({motion_text(velocity, self.layout)}): another program or port may "
            f"be driving it, or the board is not obeying"
        )

    def _ignored(self, velocity: app.Velocity, now: float) -> BoardWarning | None:
        """The first A record showing the car still FOLLOW_AFTER s after a drive letter
        (with a max_speed that is not 0): the letters are not followed."""
        since = self.moving_since
        if self.letters_ignored or since is None or now - since < FOLLOW_AFTER:
            return None
        stalled = self.params is not None and self.params.values[params.MAX_SPEED] == 0
        if stalled or self.layout.speed(velocity.values) > STILL:
            return None
        self.letters_ignored = True
        return BoardWarning(
            f"the car stands still {now - since:.1f} s after a drive letter: "
            "the control port (UART2) may have taken over the motion (§8.3); letters on "
            "this port no longer drive it until the board is reset"
        )

    def start_query(self, query: ParamQuery, now: float) -> None:
        """Begin a parameter read or set; its bytes wait in the outbox."""
        self.query = query
        query.known = None if self.params is None else self.params.values
        if self.stats.records and self.stats.recent_errors(now):
            query.link_noisy()  # a board's link that garbles records: not a non-board
        self._errors_at_start = self.stats.errors
        self._outbox += query.start(now)

    def tick(self, now: float) -> Outcome | None:
        """Let time pass: a query may resend (into the outbox) or fail."""
        if self.query is None:
            return None
        data, outcome = self.query.on_time(now)
        return self._step(data, outcome)

    def take_outbox(self) -> bytes:
        """Bytes the state wants sent."""
        data = bytes(self._outbox)
        self._outbox.clear()
        return data

    def _step(self, data: bytes, outcome: Outcome | None) -> Outcome | None:
        self._outbox += data
        query = self.query
        if outcome is not None and query is not None:
            self.query = None
            garbled = self.stats.errors - self._errors_at_start
            where = query.where
            if isinstance(outcome, QueryFailed) and not self.stats.records:
                outcome = QueryFailed(
                    f"nothing came from {where}: {outcome.text.split(': ', 1)[-1]}"
                    if not self.stats.bytes_in
                    else f"what answers at {where} is not a board: sent {{Q:P}} "
                    f"{counted(query.sent, 'time')}; {counted(self.stats.bytes_in, 'byte')} "
                    "came back and no record: another program's port (a pty path may have "
                    "been reused) or a wrong baud rate; find the car with: appmode doctor"
                )
            elif isinstance(outcome, QueryFailed) and garbled:
                outcome = QueryFailed(
                    f"{outcome.text} ({garbled} garbled records or bytes "
                    f"came meanwhile: the link is noisy)"
                )
        return outcome

    def reset_decoder(self) -> None:
        """Forget a partial record, and whether the letters are followed (after the link
        was lost: the board may restart, or the far end stop the car)."""
        self.decoder = self.layout.board_decoder()
        self.in_step = False
        self.letters_ignored = False
        self.moving_since = None

    def _apply(self, event: app.BoardEvent, now: float) -> Outcome | None:
        if isinstance(event, app.Garbage) and event.raw in self.layout.replies:
            return None  # what this firmware sends besides records (`##$`)
        if isinstance(event, app.ERRORS):
            self.outside += event.raw[: OUTSIDE - len(self.outside)]
            if not self.in_step and not event.raw.startswith(b"{"):  # no record's start
                self.stats.skipped += len(event.raw)
            else:
                self.stats.count_error(now, len(event.raw))
                if self.query is not None and self.stats.records:
                    self.query.link_noisy()
            if self.query is not None and event.raw.startswith(b"{C"):
                return self._step(*self.query.on_garbled(now))
            return None
        self.in_step = True
        self.stats.count_record(now)
        if isinstance(event, app.Velocity):
            self.velocity = event
            self.velocities.add(now, event)
        elif isinstance(event, app.Attitude):
            self.attitude = event
            self.attitudes.add(now, event)
        elif isinstance(event, app.OtherRecord) and event.letter == "B":
            self.attitudes.add(now, event)  # a profile's own B record: named by its layout
        elif isinstance(event, app.ParamsRecord):
            self.params = event
            if self.query is not None:
                return self._step(*self.query.on_params(event.values, now))
        return None
