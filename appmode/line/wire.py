"""The simulated board on a serial wire, with no I/O: the board and a line each way.

`write(data, now)` puts host bytes on the line to the board; `pump(now)` runs the board
up to `now` and returns the bytes that have reached the host. The board acts on each
byte when it would have arrived, and its telemetry leaves at slot time, paced. An
optional `tap(direction, time, data)` sees both directions as they are sent.
"""

from __future__ import annotations

from collections.abc import Callable

from appmode.board.firmware import Board
from appmode.line.pacing import Line

Tap = Callable[[str, float, bytes], None]
MAX_LAG = 1.0
"""Seconds behind after which the board catches up in one step instead of slot by slot."""
MAX_BACKLOG = 960
"""Bytes queued to the host (1 s at 9600 bps) beyond which new records are dropped."""


class Wire:
    """A Board behind a UART at `baud` (None: no pacing)."""

    def __init__(self, board: Board, baud: int | None = 9600, tap: Tap | None = None) -> None:
        self.board = board
        self.to_board = Line(baud)
        self.to_host = Line(baud)
        self.tap = tap
        self.dropped = 0

    def write(self, data: bytes, now: float) -> None:
        """Host bytes sent at `now`."""
        if data:
            if self.tap is not None:
                self.tap(">", now, data)
            self.to_board.push(data, now)

    def pump(self, now: float) -> bytes:
        """Run the board to `now`; the bytes delivered to the host by then."""
        self.run(now)
        return self.to_host.take(now)

    def pump_timed(self, now: float) -> list[tuple[float, bytes]]:
        """Like pump, with each run of bytes' delivery time."""
        self.run(now)
        return self.to_host.take_timed(now)

    def run(self, now: float) -> None:
        """Run the board to `now`: its input delivered, its records on the line."""
        board = self.board
        if now - board.next_slot() > MAX_LAG:  # stalled (suspend, debugger): catch up at once
            self._deliver(now)
            self._send(board.poll(now), now)
        while (slot := board.next_slot()) <= now:
            self._deliver(slot)
            self._send(board.poll(slot), slot)
        self._deliver(now)

    def _send(self, data: bytes, when: float) -> None:
        if data and len(self.to_host) > MAX_BACKLOG:
            self.dropped += len(data)  # the line cannot carry it: bounded, like a UART FIFO
        elif data:
            if self.tap is not None:
                self.tap("<", when, data)
            self.to_host.push(data, when)

    def _deliver(self, now: float) -> None:
        for when, data in self.to_board.take_timed(now):
            self.board.receive(data, when)

    def next_wakeup(self) -> float:
        """The next time `pump` has something to do."""
        times = [self.board.next_slot(), self.to_board.next_due(), self.to_host.next_due()]
        return min(t for t in times if t is not None)
