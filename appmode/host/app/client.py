"""The host over a link: read, set and save parameters, send, and follow records.

Thread-free: every call reads what the board has sent meanwhile and lets the host state
(`state.HostState`) resend or give up on a parameter query. A lost link is reopened
(`link.Link`). Closing sends `Z` last.
"""

from __future__ import annotations

import contextlib

from appmode.board.profiles import SHEET, Profile
from appmode.errors import AppmodeError
from appmode.host.app.query import TIMEOUT, Outcome, ParamQuery, QueryDone
from appmode.host.app.state import HostState
from appmode.host.app.stop_check import SETTLE, StopCheck
from appmode.host.events import BoardWarning, FarStop, LinkStatus
from appmode.host.link import Link, LinkLost, Opener
from appmode.host.outcomes import TRIES, QueryFailed
from appmode.line.wire import UART2, Tap
from appmode.ports.target import AnyTarget, as_target
from appmode.ports.urls import open_link
from appmode.protocol import app, session_end
from appmode.protocol.directions import PAGE_LETTERS, letter_name
from appmode.protocol.escaping import escape
from appmode.protocol.param_values import Specs
from appmode.protocol.render import motion_text

CONFIRM_STEP = 0.05
"""Seconds between looks at the clock while a stop is being confirmed."""
REFUSALS = 2
"""Connections in a row closed before a byte after which a query gives up at once."""

Event = app.BoardEvent | LinkStatus | Outcome | BoardWarning | FarStop


class Host(Link[app.BoardEvent | Outcome | BoardWarning | FarStop]):
    """A session with one board's APP port."""

    proves_return = True  # back at the first record (the board streams them)

    def __init__(
        self,
        url: AnyTarget,
        tap: Tap | None = None,
        opener: Opener = open_link,
        stop_on_close: bool = True,
        profile: Profile = SHEET,
        confirm_stop: bool = False,
    ) -> None:
        """`profile`: the board's firmware — how its records read, whether a frame stops
        the car, what to send when a stop did not take. With `confirm_stop`, closing
        checks the stop on the board's A records (`_confirm`)."""
        target = as_target(url)
        if target.simulated and target.sim_port == UART2:
            raise AppmodeError(
                f"{target} is the simulated board's control port (UART2, binary frames): this "
                "command speaks the APP protocol; leave out port=uart2"
            )
        super().__init__(target, tap, opener)
        self.stop_on_close = stop_on_close
        self.profile = profile
        self.state = HostState(profile.a_layout, profile.steer_in_frames)
        self.confirm_stop = confirm_stop
        self.stop_again = session_end.stop_again(frames_take_letters=not profile.steer_in_frames)
        """What to send when the stop did not take."""
        self.notes: list[str] = []
        """What closing had to do beyond its stop, for people."""

    def _on_lost(self) -> None:
        self.state.reset_decoder()

    def _sent(self, data: bytes) -> None:
        self.state.sent(data, self.now())

    def send_command(self, command: app.Command) -> None:
        self.send(app.encode(command))

    def _read_once(self, block: bool) -> list[Event]:
        events = self._take_pending()
        data = self._read_bytes(block)
        events += self._take_pending()
        if data:
            new = self.state.feed(data, self.now())
            if any(isinstance(event, app.RECORDS) for event in new):
                self._proven_by_output()
                events += self._take_pending()  # "is back" before what proved it
            events += new
        for stop in _far_stops(self.link):
            if stop.stopped:
                self.state.stopped_far(self.now())
            events.append(stop)
        outcome = self.state.tick(self.now())
        if isinstance(outcome, QueryFailed) and (far := _far_end_down(self.link)) is not None:
            outcome = QueryFailed(f"{outcome.text.split(': ', 1)[0]}: {far}")
        if outcome is not None:
            events.append(outcome)
        self._flush_outbox()
        return events

    def _flush_outbox(self) -> None:
        data = self.state.take_outbox()
        if data:
            with contextlib.suppress(LinkLost):  # the query times out and retries
                self.send(data)

    # ------------------------------------------------------------ parameters

    def start_query(self, query: ParamQuery) -> None:
        """Begin a read or set without waiting; its outcome comes with the events."""
        self.state.start_query(query, self.now())
        self._flush_outbox()

    def query(self, query: ParamQuery) -> tuple[int, ...]:
        """Run a read or set to its end; AppmodeError if it fails."""
        self.start_query(query)
        while True:
            if self.refused is not None and self.refusals >= REFUSALS:
                raise AppmodeError(self.refused)
            for event in self.poll(query.timeout):
                if isinstance(event, QueryDone):
                    return event.values
                if isinstance(event, QueryFailed):
                    raise AppmodeError(self.refused or event.text)

    def read_params(self, timeout: float = TIMEOUT, tries: int = TRIES) -> tuple[int, ...]:
        """Send `{Q:P}` and wait for the C record, retrying; AppmodeError if none comes."""
        return self.query(ParamQuery(None, timeout, tries, self.url, specs=self._specs))

    def set_param(self, index: int, value: int, tries: int = TRIES) -> tuple[int, ...]:
        """Set a parameter (the frame's integer, checked against the profile's table) and
        verify it by reading back; returns the parameters read."""
        return self.query(ParamQuery((index, value), TIMEOUT, tries, self.url, specs=self._specs))

    @property
    def _specs(self) -> Specs:
        return self.state.layout.params

    def save(self) -> None:
        """Send `{Q:W}`: the board saves its running parameters to flash."""
        self.send_command(app.SaveParams())

    # ------------------------------------------------------------ what it shows

    @property
    def telemetry(self) -> HostState:
        """The state of the APP records this port carries."""
        return self.state

    def in_force_text(self) -> str | None:
        """What the car was last told to do on this port, in words (None: stop)."""
        end = self.state.end
        if not (end.moving and end.letter):
            return None
        return f"{end.letter} {letter_name(PAGE_LETTERS[end.page_letter], end.letter)}"

    # ------------------------------------------------------------ end

    def _stop(self) -> bytes:
        return self.state.end.stop

    def _before_stop(self) -> None:
        if self.confirm_stop:
            self.poll_nowait()  # records from before the stop must not confirm it

    def _confirm(self) -> None:
        """With `confirm_stop`, once the board has sent A records: wait for one showing
        the car at rest; send `stop_again` while none does (`stop_check`)."""
        if not self.confirm_stop or self.state.velocity is None:
            return
        check = StopCheck(self.state.layout, self.stop_again, self.now())
        while True:
            for event in self.poll(CONFIRM_STEP):
                if isinstance(event, app.Velocity) and check.at_rest(event):
                    return
            again = check.on_time(self.now())
            if again is None:
                shown = (
                    ""
                    if check.moving is None
                    else f" ({motion_text(check.moving, self.state.layout)})"
                )
                raise AppmodeError(
                    f"the car may still be moving: it did not stop{shown} after {check.tries} "
                    f"stops, the last {escape(self.stop_again)}; the control port (UART2) may "
                    "have taken over, or the board does not obey this port: stop it by hand "
                    f"(its A records were read as the {self.state.layout.name} layout: if "
                    "that is not this board's, give its --profile)"
                )
            if again:
                self.notes.append(
                    f"the car still moved {SETTLE:g} s after the stop: sent {escape(again)}"
                )
                self.send(again)


def _far_end_down(port: object) -> str | None:
    """Why nothing can come, where the port knows it (a shared car's lost serial link)."""
    why = getattr(port, "car_link_down", None)
    return why if isinstance(why, str) else None


def _far_stops(port: object) -> list[FarStop]:
    """The stops the far end made since the last look, where the port tells them."""
    taken = getattr(port, "far_stops", None)
    return [FarStop(text, stopped) for text, stopped in taken()] if callable(taken) else []
