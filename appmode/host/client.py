"""The host over a link: read, set and save parameters, send, and follow records.

Thread-free: every call reads what the board has sent meanwhile and lets the host state
(`client.HostState`) resend or give up on a parameter query. When the link is lost the
host says so (a LinkStatus event), retries the same URL every RETRY seconds, and says so
again when it is back. Closing sends `Z` first.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator
from types import TracebackType

import serial

from appmode.errors import AppmodeError
from appmode.host.query import TIMEOUT, TRIES, Outcome, ParamQuery, QueryDone, QueryFailed
from appmode.host.state import BoardWarning, HostState, LinkStatus
from appmode.line.wire import UART2, Tap
from appmode.ports.link import is_simulated, open_link
from appmode.ports.sim import sim_side
from appmode.protocol import app, params
from appmode.protocol.layouts import VELOCITY, ALayout

RETRY = 0.5
STEP = 0.001
"""Seconds between looks at the port while waiting less than its read timeout."""

Event = app.BoardEvent | LinkStatus | Outcome | BoardWarning


class LinkLost(AppmodeError):
    """The link is down; the host is trying to get it back."""


class Host:
    """A session with one board."""

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
        self.url = url
        self.tap = tap
        self.stop_on_close = stop_on_close
        self.state = HostState(layout)
        self._clock = clock
        self._opener = opener
        self._port: serial.SerialBase | None = opener(url)
        self._origin = clock()  # after opening: an in-process sim:// board booted just now
        self._lost_at = 0.0
        self._pending: list[Event] = []

    # ------------------------------------------------------------ link

    def now(self) -> float:
        """Seconds since the session started."""
        return self._clock() - self._origin

    @property
    def connected(self) -> bool:
        return self._port is not None

    @property
    def link(self) -> serial.SerialBase | None:
        """The open port (None while the link is down)."""
        return self._port

    def _lost(self, exc: Exception) -> None:
        if self._port is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                self._port.close()
        self._port = None
        self._lost_at = self.now()
        self.state.reset_decoder()
        self._pending.append(LinkStatus(False, f"link to {self.url} lost ({exc}); retrying"))

    def _reconnect(self) -> None:
        if self.now() - self._lost_at < RETRY:
            return
        self._lost_at = self.now()
        try:
            self._port = self._opener(self.url)
        except AppmodeError:
            return
        self._pending.append(LinkStatus(True, f"link to {self.url} is back"))

    def send(self, data: bytes) -> None:
        """Write bytes to the board; LinkLost if the link is down."""
        if self._port is None:
            self._reconnect()
        if self._port is None:
            raise LinkLost(f"link to {self.url} is down; not sent: {data!r}")
        try:
            self._port.write(data)
        except (serial.SerialException, OSError) as exc:
            self._lost(exc)
            raise LinkLost(f"link to {self.url} lost while sending: {exc}") from None
        self.state.sent(data, self.now())
        if self.tap is not None:
            self.tap(">", self.now(), data)

    def send_command(self, command: app.Command) -> None:
        self.send(app.encode(command))

    def poll(self, timeout: float) -> list[Event]:
        """What arrives within `timeout` seconds: returns as soon as something does, and
        never after the deadline. A wait longer than the port's read timeout blocks in
        the port; a shorter one looks every STEP seconds, so a caller with something to
        send at the deadline (conform, replay) is not held up by the read."""
        deadline = self.now() + timeout
        while True:
            wait = None if self._port is None else self._port.timeout
            block = wait is not None and deadline - self.now() >= wait
            events = self._read_once(block=block)
            left = deadline - self.now()
            if events or left <= 0:
                return events
            if not block:
                time.sleep(min(RETRY / 5 if self._port is None else STEP, left))

    def poll_nowait(self) -> list[Event]:
        """What has arrived, without waiting."""
        return self._read_once(block=False)

    def _read_once(self, block: bool) -> list[Event]:
        if self._port is None:
            self._reconnect()
        events = self._take_pending()
        if self._port is not None:
            try:
                waiting = self._port.in_waiting
                data = self._port.read(max(1, waiting)) if block or waiting else b""
            except (serial.SerialException, OSError) as exc:
                self._lost(exc)
                data = b""
            events += self._take_pending()
            if data:
                now = self.now()
                if self.tap is not None:
                    self.tap("<", now, data)
                events += self.state.feed(data, now)
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

    def _take_pending(self) -> list[Event]:
        events, self._pending = self._pending, []
        return events

    def events(self, duration: float | None = None) -> Iterator[Event]:
        """Records, errors and link changes as they arrive, for `duration` seconds."""
        end = None if duration is None else self.now() + duration
        while end is None or self.now() < end:
            step = 0.2 if end is None else max(0.0, min(0.2, end - self.now()))
            yield from self.poll(step)

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

    def close(self) -> bytes | None:
        """Stop the car (`Z` is the last byte sent, after `{}` if a frame is open and `K`
        and the page letter if a button-page rotation may go on: SessionEnd), then
        close the port. Returns the bytes of that stop, or None if the link was down.
        A passive host (`stop_on_close=False`, a monitor) sends nothing."""
        if self._port is None:
            return None
        stop = self.state.end.stop if self.stop_on_close else b""
        try:
            if stop:
                self.send(stop)
        except LinkLost:
            return self.close()  # the port is gone: nothing was sent
        except AppmodeError:
            pass  # written; only its recording failed, which must not keep the port open
        if self._port is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                self._port.flush()
            self._port.close()
            self._port = None
        return stop

    def __enter__(self) -> Host:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
