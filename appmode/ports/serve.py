"""`appmode board`: serve simulated boards on pseudo-terminals, TCP or real ports — the
APP port and the control port (UART2) of each.

One thread, one selector, which carries each endpoint. The board keeps running (and
keeps its state) whatever the client does: a pty's other end closing, a TCP client
leaving, nobody listening.
"""

from __future__ import annotations

import contextlib
import heapq
import math
import random
import selectors
import socket
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from appmode.board.firmware import Board
from appmode.board.profiles import SHEET, Profile, board_line
from appmode.board.store import open_store
from appmode.errors import AppmodeError
from appmode.line.faults import Faults, FaultSpec
from appmode.line.wire import APP, CHASSIS, UART2, UART2_BAUD, Tap, Wire, every
from appmode.ports.endpoints import Endpoint, Log, MakeEndpoint
from appmode.ports.recording import open_recorder
from appmode.ports.schedule import INPUT_BACKLOG, Served
from appmode.ports.urls import BAUD
from appmode.ports.wakeups import exact_wakeups, select_exactly
from appmode.protocol import app
from appmode.protocol.params import SYSTEM_MODE, DriveType
from appmode.protocol.recorder import Recorder

T = TypeVar("T")
GATHER = 0.0002
"""The server wakes at whole multiples of this many seconds: boards due in the same slot
run in one wake-up (a wake-up each cost 200 boards twice the CPU), none over 0.2 ms late
for it."""


class BoardServer:
    """Serves boards from one thread and one selector: `run` until `stop` is called (from
    any thread) or KeyboardInterrupt. `lock` is held while a board runs, so another
    thread may look at a board, or `restart` it, between two steps.

    The recording (`record`) is created once every port is open: a port that cannot be
    opened leaves an existing file untouched."""

    def __init__(
        self,
        make_endpoints: list[MakeEndpoint],
        boards: list[Board],
        *,
        pace: bool,
        log: Log,
        record: str | None = None,
        directives: tuple[str, ...] = (),
        make_uart2: list[MakeEndpoint] | None = None,
        make_chassis: list[MakeEndpoint] | None = None,
        faults: FaultSpec | None = None,
        view: Tap | None = None,
    ) -> None:
        self.log = log
        self._faults = faults
        self.lock = threading.Lock()
        self._sel = selectors.DefaultSelector()
        self._endpoints: list[Endpoint] = []
        self._served: list[Served] = []
        self._by_endpoint: dict[Endpoint, tuple[int, str]] = {}
        self._due: list[float] = []  # each board's next wake-up, as queued
        self._queue: list[tuple[float, int]] = []  # (due, board): a heap; stale entries skipped
        self.lateness: list[float] | None = None
        """When a list: how late each board ran after its wake-up was due (s), appended
        (bench/many_boards.py measures the timing grid with it)."""
        self._recorder: Recorder | None = None
        self._stopped = False
        self._wake_read, self._wake_write = socket.socketpair()
        self._wake_read.setblocking(False)
        self._sel.register(self._wake_read, selectors.EVENT_READ, None)
        self._origin = time.monotonic()
        try:
            seconds = {UART2: make_uart2, CHASSIS: make_chassis}
            self._open(make_endpoints, boards, pace, record, directives, seconds, view)
        except BaseException:
            self.close()
            raise

    def _open(
        self,
        make_endpoints: list[MakeEndpoint],
        boards: list[Board],
        pace: bool,
        record: str | None,
        directives: tuple[str, ...],
        others: dict[str, list[MakeEndpoint] | None],
        view: Tap | None,
    ) -> None:
        pairs: list[dict[str, Endpoint]] = []
        for i, make in enumerate(make_endpoints):
            pair = {APP: make(self._sel, self.log)}
            self._endpoints.append(pair[APP])
            for name, makers in others.items():
                if makers is not None:
                    pair[name] = makers[i](self._sel, self.log)
                    self._endpoints.append(pair[name])
            pairs.append(pair)
        self._recorder = (
            open_recorder(
                record, 0.0, directives, background=False, layout=boards[0].profile.a_layout
            )
            if record
            else None
        )
        for pair, board in zip(pairs, boards, strict=True):
            if self._recorder is not None:
                self._recorder.follow(int(board.params[SYSTEM_MODE]), 0.0)
            bauds = {
                name: endpoint.baud or (BAUD if name == APP else UART2_BAUD)
                for name, endpoint in pair.items()
            }
            wire = Wire(
                board,
                bauds[APP] if pace else None,
                every(view, self._recorder),
                bauds.get(UART2, UART2_BAUD) if pace else None,
            )
            one = Served(
                pair,
                wire,
                dict.fromkeys(pair, False),
                faults=self._faulty(),
                phase=len(self._served) / len(boards),
            )
            self._served.append(one)
            self._due.append(math.nan)
            for name, endpoint in pair.items():
                self._by_endpoint[endpoint] = (len(self._served) - 1, name)
            self._reschedule(len(self._served) - 1)

    def _faulty(self) -> tuple[Faults, Faults] | None:
        spec = self._faults
        if spec is None or not spec.active:
            return None
        if spec.delay or spec.split:
            raise AppmodeError(
                "a served board's link takes drop, dup, corrupt and chatter faults; delay "
                "and split are sim:// only (a pty or socket already splits what it carries)"
            )
        rng = random.Random(spec.seed)
        return Faults(spec, rng), Faults(spec, rng)

    def urls(self, index: int = 0) -> dict[str, str]:
        """The URLs of board `index`'s ports, by port name (`app`, `uart2`)."""
        return {name: e.url for name, e in self._served[index].endpoints.items()}

    def details(self, index: int = 0) -> list[str]:
        """What else clients need to reach board `index` (the Bluetooth stand-in's bus)."""
        return [line for e in self._served[index].endpoints.values() for line in e.details]

    def look(self, index: int, see: Callable[[Board], T]) -> T:
        """`see(board)` for board `index` run to now, between two steps of the server."""
        with self.lock:
            one = self._served[index]
            one.wire.run(self.now())
            one.changed()
            self._reschedule(index)
            return see(one.wire.board)

    def now(self) -> float:
        """The boards' clock: seconds since the server started."""
        return time.monotonic() - self._origin

    def restart(self, index: int, make: Callable[[Board, float], Board]) -> None:
        """Power-cycle board `index`: `make(old_board, now)` builds the new board, which
        replaces the old one on the same ports; what was on its lines is lost, as in a
        power cut."""
        with self.lock:
            one = self._served[index]
            old = one.wire
            board = make(old.board, self.now())
            one.wire = Wire(
                board, old.ports[APP].to_host.baud, old.tap, old.ports[UART2].to_host.baud
            )
            if self._recorder is not None:  # APP mode and the report are never saved
                self._recorder.note(f"board {index} restarted (a power cycle)", self.now())
                self._recorder.follow(int(board.params[SYSTEM_MODE]), self.now())
            one.changed()
            self._reschedule(index)
        self._wake()

    def stop(self) -> None:
        """End `run` (from any thread)."""
        self._stopped = True
        self._wake()

    def _wake(self) -> None:
        with contextlib.suppress(OSError):
            self._wake_write.send(b"\0")

    def _woken(self) -> None:
        with contextlib.suppress(OSError):
            self._wake_read.recv(4096)

    def run(self) -> None:
        """Serve until `stop` or KeyboardInterrupt, with exact wake-ups (ports.wakeups)."""
        with exact_wakeups():  # the boards' grid points kept, also on a busy machine
            self._serve()

    def _serve(self) -> None:
        while not self._stopped:
            with self.lock:
                wake = self._step()
            if wake < math.inf:  # never before it: the slot's time is rounded
                wake = max(wake, math.ceil(wake / GATHER) * GATHER)
            timeout = max(0.0, wake - self.now())
            for key, _ in select_exactly(self._sel, timeout):
                self._receive(key)

    def _receive(self, key: selectors.SelectorKey) -> None:
        """Read what a ready port holds (at most the room its board has) and feed it."""
        endpoint: Endpoint | None = key.data
        if endpoint is None:
            self._woken()
            return
        with self.lock:
            index, name = self._by_endpoint[endpoint]
            one = self._served[index]
            room = INPUT_BACKLOG - len(one.wire.ports[name].to_board)
            data = endpoint.read(max(1, room), key.fileobj)
            if data:
                one.receive(data, self.now(), name)
                self._log_notes(one)
                one.throttle()
                self._reschedule(index)

    def _log_notes(self, one: Served) -> None:
        if not one.wire.board.notes:
            return
        for note in one.wire.board.take_notes():
            self.log(f"{note.time:10.3f}  {note.port} {note.level:<8} {note.text}")

    def _reschedule(self, index: int) -> None:
        """Queue board `index` at its next wake-up (an entry queued before is left stale)."""
        due = self._served[index].wakeup()
        dues = self._due
        if due == dues[index]:
            return  # queued already
        dues[index] = due
        if due < math.inf:
            queue = self._queue
            heapq.heappush(queue, (due, index))
            if len(queue) > 4 * len(dues) + 64:  # stale entries pile up: rebuild
                self._queue = [(d, i) for i, d in enumerate(dues) if d < math.inf]
                heapq.heapify(self._queue)

    def _step(self) -> float:
        """Run every board that is due (only those: a heap orders them); when the next
        one is."""
        now = self.now()
        queue, dues, served, lateness = self._queue, self._due, self._served, self.lateness
        ran = []
        while queue and queue[0][0] <= now:
            due, index = heapq.heappop(queue)
            if due != dues[index]:
                continue  # stale
            dues[index] = math.nan
            if lateness is not None:
                lateness.append(now - due)
            one = served[index]
            if one.pump(now):
                self._log_notes(one)
                one.throttle()
            ran.append(index)
        inf = math.inf
        for index in ran:  # as _reschedule, written out: this runs for every write
            due = served[index].wakeup()
            if due != dues[index]:
                dues[index] = due
                if due < inf:
                    heapq.heappush(queue, (due, index))
        if len(queue) > 4 * len(dues) + 64:  # stale entries pile up: rebuild
            self._queue = queue = [(d, i) for i, d in enumerate(dues) if d < inf]
            heapq.heapify(queue)
        return queue[0][0] if queue else inf

    def close(self) -> None:
        """Take in what the clients sent before the end (once, without waiting: the
        recording holds every byte written to the board before it ended), close every
        port, then the recording (what its decoders hold is written)."""
        with contextlib.suppress(OSError, ValueError):
            for key, _ in self._sel.select(0):
                self._receive(key)
        for endpoint in self._endpoints:
            endpoint.close()
        self._sel.close()
        self._wake_read.close()
        self._wake_write.close()
        if self._recorder is not None:
            self._recorder.close()


def switched_on(count: int, profile: Profile) -> list[float]:
    """When each of `count` boards served together is switched on: one by one over a
    record period, as cars are, so that their records do not all fall due at once."""
    period = profile.record_period_ms(len(app.encode(app.Velocity(0, 0, 0, 0)))) / 1000
    return [i * period / count for i in range(count)]


@dataclass(frozen=True, slots=True)
class ServeOptions:
    """What `appmode board` serves, and how."""

    app: MakeEndpoint
    """Opens each board's APP port."""
    uart2: MakeEndpoint
    """Opens each board's control port."""
    chassis: MakeEndpoint | None = None
    """Opens each board's chassis port (a WHEELTEC profile's board)."""
    count: int = 1
    profile: Profile = SHEET
    drive: DriveType | None = None
    """The drive type; None: the saved one."""
    flash: str | None = None
    """The JSON file the board saves to; None: memory."""
    pace: bool = True
    """Send at the line rates."""
    record: str | None = None
    quiet: bool = False
    baud: int | None = None
    """The APP port's rate, when not 9600 (for the banner)."""

    def banner(self, drive: DriveType) -> str:
        """What is served (boards of `drive` type), in a line."""
        profile = self.profile
        if profile.file is not None:
            saves = f"flash {self.flash or 'in memory'}" if profile.saves else "saves nothing"
            body = f"{saves}, its records and parameters only: no physics for this profile"
            if profile.chassis is not None:
                spec = profile.chassis
                stops = f"{spec.timeout_ms} ms" if spec.timeout_ms else "never"
                body = (
                    f"{saves}, a {spec.kind} chassis (boot {spec.boot_ms / 1000:g} s, "
                    f"stops without frames after: {stops})"
                )
        elif profile.drive_types:
            body = f"{drive.cli_name} drive, flash {self.flash or 'in memory'}"
        else:
            body = "no drive types, saves nothing"
        pace = "paced at the line rate" if self.pace else "not paced"
        plural = "s" if self.count > 1 else ""
        text = f"simulated board{plural}, {profile.name} profile, {body}, {pace}"
        return text + (f", APP port at {self.baud} bps" if self.baud is not None else "")

    @property
    def directives(self) -> tuple[str, ...]:
        """The recording's `@board` line: what a replay needs of the board."""
        return board_line(self.profile, self.drive.cli_name if self.drive else None)


def run_board(options: ServeOptions, view: Tap | None = None) -> int:
    """Build the board(s) and serve until interrupted (KeyboardInterrupt); print each
    port's line (`port: …`, then `uart2: …`) for clients to open. A live `view` sees the
    first board's bytes."""

    def log(text: str) -> None:
        if not options.quiet:
            print(f"board: {text}", file=sys.stderr, flush=True)

    profile = options.profile
    profile.check(drive=options.drive is not None, flash=options.flash is not None)
    boards = [
        Board(open_store(options.flash), drive=options.drive, profile=profile, now=on)
        for on in switched_on(options.count, profile)
    ]
    try:
        server = BoardServer(
            [options.app] * options.count,
            boards,
            pace=options.pace,
            log=log,
            record=options.record,
            directives=options.directives,
            make_uart2=[options.uart2] * options.count,
            make_chassis=[options.chassis] * options.count if options.chassis else None,
            view=view,
        )
        try:
            for i in range(options.count):
                for name, url in server.urls(i).items():
                    print(f"{'port' if name == APP else name}: {url}", flush=True)
                for line in server.details(i):
                    print(line, flush=True)
            log(options.banner(boards[0].drive_type))
            server.run()
        finally:
            server.close()
    except KeyboardInterrupt:
        log("stopped")
    finally:
        for board in boards:
            board.store.close()
    return 0
