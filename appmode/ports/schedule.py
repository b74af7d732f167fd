"""One board being served: its endpoints, its wire, and when it next wakes.

On a paced line a board wakes on a grid of RUN seconds: it runs to then, and the bytes
whose stop bit is done are written — never early, never more than RUN of wire time at
once. Boards served together spread their grid points (`phase`), so that one pass of
the server does not run them all at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from appmode.line.faults import Faults
from appmode.line.wire import APP, CHASSIS, PORTS, UART2, Wire
from appmode.ports.endpoints import Endpoint

RUN = {APP: 0.004, UART2: 0.002, CHASSIS: 0.002}
"""Seconds of wire time written at most at once to a paced client: bytes trickle in as
from a real UART (a C record over 32 ms at 9600 bps), not a record at a time. On UART2
a burst shorter than a run (a read's 6-byte reply, due in its 10 ms tick, §11) is
written whole as soon as its last stop bit is done."""
INPUT_BACKLOG = 256
"""Bytes received but not yet on the simulated line beyond which the server stops reading:
the rest waits in the pty or socket, and a writer faster than 9600 bps is held back, as
by a real line."""


@dataclass
class Served:
    """One board being served: an endpoint for each port it serves, and its wire."""

    endpoints: dict[str, Endpoint]
    wire: Wire
    paused: dict[str, bool]
    faults: tuple[Faults, Faults] | None = None
    """A faulty link: (to the board, to the host), applied to every port's bytes."""
    phase: float = 0.0
    """Where in each RUN this board's grid points fall (0…1): boards served together
    spread over the grid, so that a pass does not run them all at once."""
    board_due: float = -math.inf
    """When the board itself next has something to do, as `wakeup` last found: before
    then a pump only writes what its lines deliver."""
    sends: tuple[float, float, float] | None = None
    """When the board next sends on each port, as it said since it last ran; None: to
    be asked (`changed`)."""

    def changed(self) -> None:
        """The board ran, or was replaced, outside `pump`: ask it again when it sends."""
        self.sends = None
        if self.wire is not self._wired:  # replaced (a power cycle): its lines are new
            self._wire_up()

    def __post_init__(self) -> None:
        self._wire_up()

    def _wire_up(self) -> None:
        """What `pump` and `wakeup` look at on every pass, looked up once for the wire."""
        ports = self.wire.ports
        self._wired = self.wire
        self._grid = tuple(
            (index, name, RUN[name], self.phase * RUN[name], ports[name])
            for index, name in enumerate(PORTS)
            if name in self.endpoints
        )
        """(index in `sends`, name, run, the grid's offset, port) of each port served."""
        self._outputs = tuple((ports[name].to_host, e) for name, e in self.endpoints.items())
        """(line to the host, endpoint) of each port served."""
        self._inputs = tuple(port.to_board for port in ports.values())

    def wakeup(self) -> float:
        """When this board next has something to do. On a paced line that is a point of a
        grid of RUN seconds: the board has run to then (every byte and record at its own
        time) and the bytes whose stop bit is done are written, never early, never more
        than RUN of wire time at once, and one wake-up serves every board due then."""
        wire = self.wire
        sends = self.sends
        if sends is None:  # the board ran: else its plans are as they were
            sends = self.sends = wire.board.next_sends()
        self.board_due = min(sends)
        due = inf = math.inf
        for index, name, run, offset, port in self._grid:
            to_host, to_board = port.to_host, port.to_board
            mine = sends[index]
            if mine == inf and not to_host.bursts and not to_board.bursts:
                continue  # nothing planned, nothing on its lines (and so no read pending)
            step = to_host.byte_time
            mine += step  # the port's next output: its first byte
            first = to_host.next_due() if to_host.bursts else None
            if first is not None and first < mine:
                mine = first
            if to_board.bursts:
                received = to_board.next_due()
                if received is not None and received < mine:
                    mine = received
            if step and mine < math.inf:
                mine = math.ceil((mine - offset) / run - 1e-9) * run + offset
            if name == UART2 and step:
                # a reply is due within its tick: run the board at the slot, and write a
                # burst shorter than a run whole when its last stop bit is done
                mine = min(mine, wire.board.next_reply())
                last = to_host.last_due()
                if first is not None and last is not None and last - first < run:
                    mine = min(mine, last)
            if mine < due:
                due = mine
        return due

    def pump(self, now: float) -> bool:
        """Write what the lines deliver by `now`, running the board first when it is due
        or has input; whether it ran (else it made no notes and its input is as it was)."""
        ran = now >= self.board_due or any(line.bursts for line in self._inputs)
        if ran:
            self.sends = self.wire.run(now)
        faults = self.faults
        for line, endpoint in self._outputs:
            if not line.bursts:
                continue
            out = line.take(now)
            if out and faults is not None:
                out = faults[1].apply(out)
            if out:
                endpoint.write(out)
        return ran

    def receive(self, data: bytes, now: float, port: str) -> None:
        self.pump(now)  # what was due before these bytes came
        if self.faults is not None:
            data = self.faults[0].apply(data)
        self.wire.write(data, now, port)

    def throttle(self) -> None:
        """Read no more while INPUT_BACKLOG bytes wait for the simulated line."""
        if not (any(line.bursts for line in self._inputs) or any(self.paused.values())):
            return  # nothing waits, nothing is paused
        for name, endpoint in self.endpoints.items():
            full = len(self.wire.ports[name].to_board) >= INPUT_BACKLOG
            if full != self.paused[name]:
                endpoint.pause(full)
                self.paused[name] = full
