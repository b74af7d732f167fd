"""The simulated board on its serial wires, with no I/O: the board and a line each way
on each of its two ports (the APP port, UART3, and the control port, UART2).

`write(data, now, port)` puts host bytes on the line to the board; `pump(now, port)`
runs the board up to `now` and returns the bytes that have reached the host on that
port. The board acts on each byte when it would have arrived (the two ports' bytes in
time order), and what it sends leaves at slot time, paced. An optional `tap(direction,
time, data)` sees every direction as it is sent: `>` and `<` on the APP port, `2>` and
`2<` on UART2.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from appmode.line.pacing import Line

if TYPE_CHECKING:  # a host that names the ports imports no board
    from appmode.board.firmware import Board

Tap = Callable[[str, float, bytes], None]


def every(*taps: Tap | None) -> Tap | None:
    """One tap that feeds each of `taps` in turn (those not None); None if none is."""
    given = [tap for tap in taps if tap is not None]
    if len(given) <= 1:
        return given[0] if given else None

    def tap(direction: str, at: float, data: bytes) -> None:
        for one in given:
            one(direction, at, data)

    return tap


APP, UART2, CHASSIS = "app", "uart2", "chassis"
PORTS = (APP, UART2, CHASSIS)
"""A board's ports, in the order `Board.next_sends` gives them."""
APP_BAUD = 9600
UART2_BAUD = 115200
CHASSIS_BAUD = 115200
MAX_LAG = 1.0
"""Seconds behind after which the board catches up in one step instead of slot by slot."""
MAX_BACKLOG = {APP: APP_BAUD // 10, UART2: UART2_BAUD // 10, CHASSIS: CHASSIS_BAUD // 10}
"""Bytes queued to the host (1 s of the line) beyond which new bytes are dropped."""


@dataclass
class Port:
    """One port's two lines and its tap directions."""

    to_board: Line
    to_host: Line
    sent: str
    received: str
    dropped: int = field(default=0)


class Wire:
    """A Board behind its two UARTs at `baud` and `baud2` (None: no pacing)."""

    def __init__(
        self,
        board: Board,
        baud: int | None = APP_BAUD,
        tap: Tap | None = None,
        baud2: int | None = UART2_BAUD,
    ) -> None:
        self.board = board
        chassis = CHASSIS_BAUD if baud2 is not None else None
        self.ports = {
            APP: Port(Line(baud), Line(baud), ">", "<"),
            UART2: Port(Line(baud2), Line(baud2), "2>", "2<"),
            CHASSIS: Port(Line(chassis), Line(chassis), "c>", "c<"),
        }
        self.tap = tap

    @property
    def to_board(self) -> Line:
        """The APP port's line to the board."""
        return self.ports[APP].to_board

    @property
    def to_host(self) -> Line:
        """The APP port's line to the host."""
        return self.ports[APP].to_host

    @property
    def dropped(self) -> int:
        return sum(p.dropped for p in self.ports.values())

    def write(self, data: bytes, now: float, port: str = APP) -> None:
        """Host bytes sent at `now`."""
        if data:
            line = self.ports[port]
            if self.tap is not None:
                self.tap(line.sent, now, data)
            line.to_board.push(data, now)

    def pump(self, now: float, port: str = APP) -> bytes:
        """Run the board to `now`; the bytes delivered to the host by then."""
        self.run(now)
        return self.ports[port].to_host.take(now)

    def pump_timed(self, now: float, port: str = APP) -> list[tuple[float, bytes]]:
        """Like pump, with each run of bytes' delivery time."""
        self.run(now)
        return self.ports[port].to_host.take_timed(now)

    def run(self, now: float) -> tuple[float, float, float]:
        """Run the board to `now`: its input delivered, what it sends on the lines. When
        the board next sends on each port (`Board.next_sends`), as it stands after."""
        board = self.board
        inputs = [port.to_board for port in self.ports.values()]
        sends = board.next_sends()
        slot = min(sends)
        if now - slot > MAX_LAG:  # stalled (suspend, debugger): catch up at once
            self._deliver(now)
            self._send(now)
            sends = board.next_sends()
            slot = min(sends)
        while slot <= now:
            if any(line.bursts for line in inputs):
                self._deliver(slot)
            self._send(slot)
            sends = board.next_sends()
            slot = min(sends)
        if any(line.bursts for line in inputs):
            self._deliver(now)
            sends = board.next_sends()  # what came may ask for a reply
        return sends

    def _send(self, when: float) -> None:
        for name, data in zip(PORTS, self.board.poll_ports(when), strict=True):
            if data:
                self._queue(name, data, when)

    def _queue(self, name: str, data: bytes, when: float) -> None:
        """What the board sent on port `name` at `when` goes on the line to the host."""
        port = self.ports[name]
        line = port.to_host
        if len(line) > MAX_BACKLOG[name]:
            port.dropped += len(data)  # the line cannot carry it: bounded, like a FIFO
            return
        if self.tap is not None:
            self.tap(port.received, when, data)
        line.push(data, when)

    def _deliver(self, now: float) -> None:
        board = self.board
        takers = (board.receive, board.receive_uart2, board.receive_chassis)
        arrived = [
            (when, which, data)
            for which, port in enumerate(self.ports.values())
            if port.to_board.bursts
            for when, data in port.to_board.take_timed(now)
        ]
        arrived.sort(key=lambda item: (item[0], item[1]))  # the ports' bytes in time order
        for when, which, data in arrived:
            takers[which](data, when)

    def next_wakeup(self) -> float:
        """The next time `pump` has something to do."""
        times = [self.board.next_slot()]
        for port in self.ports.values():
            due = (port.to_board.next_due(), port.to_host.next_due())
            times += [t for t in due if t is not None]
        return min(times)
