"""The host over a link: read, set and save parameters, send, and follow records.

Thread-free: every call reads what the board has sent meanwhile and lets the host state
(`state.HostState`) resend or give up on a parameter query. A lost link is reopened
(`link.Link`). Closing sends `Z` last.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable

import serial

from appmode.errors import AppmodeError
from appmode.host.link import Link, LinkLost
from appmode.host.query import TIMEOUT, TRIES, Outcome, ParamQuery, QueryDone, QueryFailed
from appmode.host.state import BoardWarning, HostState, LinkStatus
from appmode.line.wire import UART2, Tap
from appmode.ports.link import is_simulated, open_link
from appmode.ports.sim import sim_side
from appmode.protocol import app, params
from appmode.protocol.layouts import VELOCITY, ALayout

Event = app.BoardEvent | LinkStatus | Outcome | BoardWarning


class Host(Link[app.BoardEvent | Outcome | BoardWarning]):
    """A session with one board's APP port."""

    def __init__(
        self,
        url: str,
        tap: Tap | None = None,
        clock: Callable[[], float] = time.monotonic,
        opener: Callable[[str], serial.SerialBase] = open_link,
        stop_on_close: bool = True,
        layout: ALayout = VELOCITY,
    ) -> None:
        if is_simulated(url) and sim_side(url) == UART2:
            raise AppmodeError(
                f"{url} is the simulated board's control port (UART2, binary frames): this "
                "command speaks the APP protocol; leave out port=uart2"
            )
        super().__init__(url, tap, clock, opener)
        self.stop_on_close = stop_on_close
        self.state = HostState(layout)

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
            events += self.state.feed(data, self.now())
        outcome = self.state.tick(self.now())
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
            for event in self.poll(query.timeout):
                if isinstance(event, QueryDone):
                    return event.values
                if isinstance(event, QueryFailed):
                    raise AppmodeError(event.text)

    def read_params(self, timeout: float = TIMEOUT, tries: int = TRIES) -> tuple[int, ...]:
        """Send `{Q:P}` and wait for the C record, retrying; AppmodeError if none comes."""
        return self.query(ParamQuery(None, timeout, tries, self.url))

    def set_param(self, index: int, value: int, tries: int = TRIES) -> tuple[int, ...]:
        """Set a parameter and verify it by reading back; returns the parameters read."""
        params.check_value(index, value)
        return self.query(ParamQuery((index, value), TIMEOUT, tries, self.url))

    def save(self) -> None:
        """Send `{Q:W}`: the board saves its running parameters to flash."""
        self.send_command(app.SaveParams())

    # ------------------------------------------------------------ end

    def _stop(self) -> bytes:
        return self.state.end.stop
