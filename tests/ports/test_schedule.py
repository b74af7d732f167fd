"""The boards server's schedule on a virtual clock: what each port is given, and when."""

from __future__ import annotations

import random

import pytest

from appmode.board.firmware import Board
from appmode.line.wire import APP, UART2
from appmode.ports.schedule import Served
from appmode.ports.serve import BoardServer
from appmode.protocol import control, settings
from appmode.protocol.params import DriveType

Writes = list[tuple[float, str, bytes]]


class Clock:
    now = 0.0


class Taken:
    """An endpoint that keeps what it is given, with the clock's time."""

    baud = None

    def __init__(self, clock: Clock, name: str, writes: Writes) -> None:
        self.clock, self.name, self.writes = clock, name, writes

    def write(self, data: bytes) -> None:
        self.writes.append((self.clock.now, self.name, data))

    def pause(self, paused: bool) -> None:
        """Never paused here."""

    def close(self) -> None:
        """Nothing to close."""


def serve(board: Board, clock: Clock, writes: Writes) -> BoardServer:
    server = BoardServer(
        [lambda sel, log: Taken(clock, APP, writes)],
        [board],
        pace=True,
        log=lambda text: None,
        make_uart2=[lambda sel, log: Taken(clock, UART2, writes)],
    )
    server.now = lambda: clock.now  # type: ignore[method-assign]
    return server


def run(
    server: BoardServer, clock: Clock, until: float, inputs: list[tuple[float, str, bytes]]
) -> None:
    """Serve to `until`, each input given to the board at its time."""
    pending = sorted(inputs)
    for _ in range(100_000):  # a schedule that stops moving forward fails, never hangs
        if clock.now >= until:
            return
        while pending and pending[0][0] <= clock.now:
            _, port, data = pending.pop(0)
            server._served[0].receive(data, clock.now, port)
            server._reschedule(0)
        wake = server._step()
        clock.now = min(wake, pending[0][0] if pending else until, until)
    raise AssertionError(f"the schedule stopped at {clock.now:.6f} s")


def scenario() -> list[tuple[float, str, bytes]]:
    rng = random.Random(5)
    frames = [
        (UART2, control.encode(control.SetSetting(settings.BY_NAME["system_mode"], 0x41))),
        (UART2, control.encode(control.velocity(DriveType.MECANUM, y=300))),
        (UART2, control.encode(control.read("speed_a"))),
        (UART2, control.encode(control.SetSetting(settings.BY_NAME["system_mode"], 0x01))),
        (APP, b"{Q:P}"),
        (APP, b"{8:193}"),  # APP mode on: records move to UART2
        (APP, b"{8:65}"),
    ]
    times = sorted(rng.uniform(0.0, 6.0) for _ in range(40))
    return [(t, *rng.choice(frames)) for t in times]


def test_the_board_is_asked_when_it_sends_only_after_it_ran(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Between its runs a served board's plans are kept, not asked for on every pass:
    what each port is given, and when, is what asking every pass gives."""

    def served(ask_every_pass: bool) -> Writes:
        if ask_every_pass:
            wakeup = Served.wakeup
            monkeypatch.setattr(Served, "wakeup", lambda self: (self.changed(), wakeup(self))[1])
        clock, writes = Clock(), []
        server = serve(Board(drive=DriveType.MECANUM), clock, writes)
        run(server, clock, 8.0, scenario())
        server.close()
        monkeypatch.undo()
        return writes

    kept = served(ask_every_pass=False)
    assert len({port for _, port, _ in kept}) == 2 and len(kept) > 500
    assert kept == served(ask_every_pass=True)


def test_a_restarted_board_sends_as_one_switched_on_then() -> None:
    """restart() puts a new board on the ports: it sends when a board switched on at that
    moment would, not when the old board planned to."""

    def first_writes(restart_at: float | None) -> Writes:
        clock, writes = Clock(), []
        on = 0.0 if restart_at is not None else 2.013
        server = serve(Board(now=on), clock, writes)
        clock.now = on
        if restart_at is not None:
            run(server, clock, restart_at, [])
            server.restart(0, lambda old, now: Board(now=now))
            writes.clear()
        run(server, clock, 2.5, [])
        server.close()
        return writes

    restarted = first_writes(2.013)
    assert restarted and restarted == first_writes(None)
