"""`appmode board`: serve the simulated board on a pseudo-terminal, TCP, or a real port,
and its control port (UART2) on a second one.

One thread, one selector. The board keeps running (and keeps its state) whatever the
client does: a pty's other end closing, a TCP client leaving, nobody listening.
"""

from __future__ import annotations

import contextlib
import errno
import heapq
import math
import os
import random
import selectors
import socket
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import TypeVar

import serial

from appmode.board.firmware import Board
from appmode.board.profiles import SHEET, Profile, profile_named
from appmode.board.store import open_store
from appmode.errors import AppmodeError
from appmode.files import temporary_beside
from appmode.line.faults import Faults, FaultSpec
from appmode.line.uart import misread
from appmode.line.wire import APP, PORTS, UART2, UART2_BAUD, Wire
from appmode.ports.urls import BAUD, NO_PTY, explain_open_error, parse_device
from appmode.protocol import app, params
from appmode.protocol.params import SYSTEM_MODE, DriveType
from appmode.protocol.transcript import Recorder

Log = Callable[[str], None]
T = TypeVar("T")
RUN = {APP: 0.004, UART2: 0.002}
"""Seconds of wire time written at most at once to a paced client: bytes trickle in as
from a real UART (a C record over 32 ms at 9600 bps), not a record at a time. On UART2
a burst shorter than a run (a read's 6-byte reply, due in its 10 ms tick, §11) is
written whole as soon as its last stop bit is done."""
INPUT_BACKLOG = 256
"""Bytes received but not yet on the simulated line beyond which the server stops reading:
the rest waits in the pty or socket, and a writer faster than 9600 bps is held back, as
by a real line."""


class Overrun:
    """Writes what the OS takes; what it will not take (a full pty or socket buffer:
    nobody reads) is dropped, as a UART drops what nobody reads, never retried. The log
    says when dropping starts and how much was dropped when reading resumes."""

    def __init__(self, log: Log, where: str) -> None:
        self._log = log
        self._where = where
        self.dropped = 0
        """Bytes dropped in the current run of drops."""

    def write(self, data: bytes, write: Callable[[bytes], int]) -> None:
        while data:
            try:
                data = data[write(data) :]
            except BlockingIOError:
                if not self.dropped:
                    self._log(f"nobody reads {self._where}: what the board sends is dropped")
                self.dropped += len(data)
                return
        if self.dropped:
            self._log(f"{self._where} is read again; {self.dropped} bytes were dropped")
            self.dropped = 0


class PtyEndpoint:
    """A new pseudo-terminal; clients open its slave path like a serial port.

    The server holds the slave open itself, so the master never sees EIO when a client
    closes, and the path stays the same for the next client.
    """

    def __init__(
        self,
        sel: selectors.BaseSelector,
        log: Log,
        link: str | None = None,
        baud: int | None = None,
    ) -> None:
        try:  # POSIX only: imported where a pty is made, so Windows can serve on TCP
            import tty

            from appmode.ports.newpty import client_baud
        except ImportError:
            raise AppmodeError(
                f"{NO_PTY}: serve on TCP with --listen HOST:PORT and --listen2 HOST:PORT"
            ) from None

        try:
            self._master, self._slave = os.openpty()  # pty.openpty hides the errno
        except OSError as exc:
            if exc.errno in (errno.EMFILE, errno.ENFILE):
                raise AppmodeError(
                    f"cannot open another pseudo-terminal: this process may open no more "
                    f"files ({exc.strerror}); raise the open-file limit (ulimit -n) or "
                    f"serve fewer boards (--count)"
                ) from None
            raise AppmodeError(
                f"cannot open another pseudo-terminal: {exc.strerror or exc}; the system "
                f"has no more ptys: serve fewer boards (--count), or close other terminals"
            ) from None
        tty.setraw(self._slave)  # no echo, no line editing: bytes pass untouched
        os.set_blocking(self._master, False)
        self._write_master = partial(os.write, self._master)
        self.baud = baud
        """The line rate of the UART this pty stands for; None: bytes pass at any rate."""
        self._client_baud = client_baud
        self.url = os.ttyname(self._slave)
        self._out = Overrun(log, self.url)
        self._link = link
        self._link_target = _lasting_path(self._slave, self.url)
        if link is not None:
            _symlink(self._link_target, link)
            log(f"{link} -> {self.url}")
        self._sel = sel
        sel.register(self._master, selectors.EVENT_READ, self._read)

    def pause(self, paused: bool) -> None:
        """Stop (or go on) reading: what is not read waits in the pty."""
        if paused:
            self._sel.unregister(self._master)
        else:
            self._sel.register(self._master, selectors.EVENT_READ, self._read)

    def _read(self, size: int) -> bytes:
        try:
            data = os.read(self._master, size)
        except (BlockingIOError, InterruptedError):
            return b""
        return self._misread(data, to_board=True)

    def write(self, data: bytes) -> None:
        self._out.write(self._misread(data, to_board=False), self._write_master)

    def _misread(self, data: bytes, *, to_board: bool) -> bytes:
        """With a line rate, what each side reads when the client set another one."""
        if self.baud is None or not data:
            return data
        client = self._client_baud(self._slave)
        if client is None:  # a rate termios cannot name: take it as matching
            return data
        return misread(data, client, self.baud) if to_board else misread(data, self.baud, client)

    def close(self) -> None:
        link = self._link
        if link is not None and os.path.islink(link) and os.readlink(link) == self._link_target:
            os.unlink(link)
        os.close(self._master)
        os.close(self._slave)


def _lasting_path(fd: int, device: str) -> str:
    """A path to the pty that lasts only as long as this board: on Linux the board's own
    descriptor under /proc, so a link left by a board that died leads nowhere (its pty
    number may already be another program's); elsewhere the device."""
    path = f"/proc/{os.getpid()}/fd/{fd}"
    return path if os.path.realpath(path) == device else device


def _symlink(target: str, link: str) -> None:
    """Point `link` at `target`, replacing an older link atomically (not a real file)."""
    if os.path.exists(link) and not os.path.islink(link):
        raise AppmodeError(f"--link {link}: a file is already there; choose another path")
    tmp = temporary_beside(Path(link))
    try:
        os.symlink(target, tmp)
        os.replace(tmp, link)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise AppmodeError(f"--link {link}: cannot create the link: {exc.strerror}") from None


class TcpEndpoint:
    """A TCP listener serving one client at a time; others are refused while it stays."""

    def __init__(
        self,
        sel: selectors.BaseSelector,
        log: Log,
        host: str,
        port: int,
        baud: int | None = None,
    ) -> None:
        self._sel = sel
        self._log = log
        self.baud = baud
        """The line rate it is paced at; None: the port's own."""
        try:
            self._listener = socket.create_server((host, port))
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                raise AppmodeError(
                    f"TCP port {host}:{port} is already in use: pick another with --listen "
                    f"HOST:PORT (port 0 picks a free one), or stop the program using it"
                ) from None
            raise AppmodeError(f"cannot listen on {host}:{port}: {exc.strerror}") from None
        self._listener.setblocking(False)
        bound_host, bound_port = self._listener.getsockname()[:2]
        self.url = f"socket://{bound_host}:{bound_port}"
        self._client: socket.socket | None = None
        self._out = Overrun(log, "the TCP client")
        self._paused = False
        sel.register(self._listener, selectors.EVENT_READ, self._accept)

    def pause(self, paused: bool) -> None:
        """Stop (or go on) reading the client: what is not read waits in the socket."""
        self._paused = paused
        if self._client is not None:
            if paused:
                self._sel.unregister(self._client)
            else:
                self._sel.register(self._client, selectors.EVENT_READ, self._read)

    def _accept(self, size: int) -> bytes:
        try:
            conn, peer = self._listener.accept()
        except (BlockingIOError, InterruptedError):
            return b""
        if self._client is not None:
            self._log(f"refused a client from {peer[0]}:{peer[1]}: one client at a time")
            conn.close()
            return b""
        conn.setblocking(False)
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._client = conn
        if not self._paused:
            self._sel.register(conn, selectors.EVENT_READ, self._read)
        self._log(f"client connected from {peer[0]}:{peer[1]}")
        return b""

    def _read(self, size: int) -> bytes:
        if self._client is None:  # dropped earlier in this pass (a write to it failed)
            return b""
        try:
            data = self._client.recv(size)
        except (BlockingIOError, InterruptedError):
            return b""
        except OSError as exc:
            self._drop(f"client connection lost ({exc.strerror})")
            return b""
        if not data:
            self._drop("client disconnected")
        return data

    def write(self, data: bytes) -> None:
        if self._client is None:
            return
        client = self._client
        try:
            self._out.write(data, client.send)
        except OSError as exc:
            self._drop(f"client connection lost ({exc.strerror})")

    def _drop(self, why: str) -> None:
        self._out.dropped = 0
        if self._client is not None:
            if not self._paused:
                self._sel.unregister(self._client)
            self._client.close()
            self._client = None
            self._log(f"{why}; waiting for the next client")

    def close(self) -> None:
        if self._client is not None:
            self._client.close()
        self._listener.close()


class SerialEndpoint:
    """A real serial port (a USB-UART, with a Bluetooth module for the phone app)."""

    def __init__(
        self, sel: selectors.BaseSelector, log: Log, device: str, baud: int = BAUD
    ) -> None:
        path, baud = parse_device(device, baud)
        try:
            self._port = serial.Serial(path, baudrate=baud, timeout=0, exclusive=True)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise AppmodeError(explain_open_error(path, exc)) from None
        self.url = path
        self.baud: int | None = baud
        self._sel = sel
        sel.register(self._port.fileno(), selectors.EVENT_READ, self._read)

    def pause(self, paused: bool) -> None:
        """Stop (or go on) reading: what is not read waits in the OS buffer."""
        if paused:
            self._sel.unregister(self._port.fileno())
        else:
            self._sel.register(self._port.fileno(), selectors.EVENT_READ, self._read)

    def _read(self, size: int) -> bytes:
        data: bytes = self._port.read(max(1, min(size, self._port.in_waiting)))
        return data

    def write(self, data: bytes) -> None:
        if data:
            self._port.write(data)

    def close(self) -> None:
        self._port.close()


Endpoint = PtyEndpoint | TcpEndpoint | SerialEndpoint


def parse_listen(text: str, option: str = "--listen") -> tuple[str, int]:
    """`PORT` or `HOST:PORT` (host 127.0.0.1 by default)."""
    host, _, port = text.rpartition(":")
    number = params.whole(port)
    if number is None or number > 65535:
        raise AppmodeError(f"{option} {text!r}: expected HOST:PORT or PORT, e.g. 127.0.0.1:5000")
    return host.strip("[]") or "127.0.0.1", number


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

    def wakeup(self) -> float:
        """When this board next has something to do. On a paced line that is a point of a
        grid of RUN seconds: the board has run to then (every byte and record at its own
        time) and the bytes whose stop bit is done are written, never early, never more
        than RUN of wire time at once, and one wake-up serves every board due then."""
        wire = self.wire
        board = wire.board
        sends = board.next_sends()
        self.board_due = min(sends)
        due = math.inf
        for index, name in enumerate(PORTS):
            if name not in self.endpoints:
                continue
            port = wire.ports[name]
            to_host = port.to_host
            step = to_host.byte_time
            mine = sends[index] + step  # the port's next output: its first byte
            first = to_host.next_due()
            if first is not None and first < mine:
                mine = first
            received = port.to_board.next_due()
            if received is not None and received < mine:
                mine = received
            if step and mine < math.inf:
                run = RUN[name]
                offset = self.phase * run
                mine = math.ceil((mine - offset) / run - 1e-9) * run + offset
            if name == UART2 and step:
                # a reply is due within its tick: run the board at the slot, and write a
                # burst shorter than a run whole when its last stop bit is done
                mine = min(mine, board.next_reply())
                last = to_host.last_due()
                if first is not None and last is not None and last - first < RUN[name]:
                    mine = min(mine, last)
            if mine < due:
                due = mine
        return due

    def pump(self, now: float) -> None:
        wire = self.wire
        ports = wire.ports
        if now >= self.board_due or ports[APP].to_board or ports[UART2].to_board:
            wire.run(now)
        for name, endpoint in self.endpoints.items():
            line = wire.ports[name].to_host
            out = line.take(now) if line else b""
            if out and self.faults is not None:
                out = self.faults[1].apply(out)
            if out:
                endpoint.write(out)

    def receive(self, data: bytes, now: float, port: str) -> None:
        self.pump(now)  # what was due before these bytes came
        if self.faults is not None:
            data = self.faults[0].apply(data)
        self.wire.write(data, now, port)

    def throttle(self) -> None:
        """Read no more while INPUT_BACKLOG bytes wait for the simulated line."""
        ports = self.wire.ports
        if not (ports[APP].to_board or ports[UART2].to_board or any(self.paused.values())):
            return  # nothing waits, nothing is paused
        for name, endpoint in self.endpoints.items():
            full = len(self.wire.ports[name].to_board) >= INPUT_BACKLOG
            if full != self.paused[name]:
                endpoint.pause(full)
                self.paused[name] = full


MakeEndpoint = Callable[[selectors.BaseSelector, Log], Endpoint]


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
        faults: FaultSpec | None = None,
    ) -> None:
        self.log = log
        self._faults = faults
        self.lock = threading.Lock()
        self._sel = selectors.DefaultSelector()
        self._endpoints: list[Endpoint] = []
        self._served: list[Served] = []
        self._by_endpoint: dict[int, tuple[int, str]] = {}
        self._due: list[float] = []  # each board's next wake-up, as queued
        self._queue: list[tuple[float, int]] = []  # (due, board): a heap; stale entries skipped
        self.lateness: list[float] | None = None
        """When a list: how late each board ran after its wake-up was due (s), appended
        (bench/many_boards.py measures the timing grid with it)."""
        self._recorder: Recorder | None = None
        self._stopped = False
        self._wake_read, self._wake_write = socket.socketpair()
        self._wake_read.setblocking(False)
        self._sel.register(self._wake_read, selectors.EVENT_READ, self._woken)
        self._origin = time.monotonic()
        try:
            self._open(make_endpoints, boards, pace, record, directives, make_uart2)
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
        make_uart2: list[MakeEndpoint] | None,
    ) -> None:
        pairs: list[dict[str, Endpoint]] = []
        for i, make in enumerate(make_endpoints):
            pair = {APP: make(self._sel, self.log)}
            self._endpoints.append(pair[APP])
            if make_uart2 is not None:
                pair[UART2] = make_uart2[i](self._sel, self.log)
                self._endpoints.append(pair[UART2])
            pairs.append(pair)
        self._recorder = Recorder.create(record, 0.0, directives) if record else None
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
                self._recorder,
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
                self._by_endpoint[id(endpoint)] = (len(self._served) - 1, name)
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

    def look(self, index: int, see: Callable[[Board], T]) -> T:
        """`see(board)` for board `index` run to now, between two steps of the server."""
        with self.lock:
            wire = self._served[index].wire
            wire.run(self.now())
            self._reschedule(index)
            return see(wire.board)

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
            one.wire = Wire(
                make(old.board, self.now()),
                old.ports[APP].to_host.baud,
                old.tap,
                old.ports[UART2].to_host.baud,
            )
            self._reschedule(index)
        self._wake()

    def stop(self) -> None:
        """End `run` (from any thread)."""
        self._stopped = True
        self._wake()

    def _wake(self) -> None:
        with contextlib.suppress(OSError):
            self._wake_write.send(b"\0")

    def _woken(self, size: int) -> bytes:
        with contextlib.suppress(OSError):
            self._wake_read.recv(4096)
        return b""

    def run(self) -> None:
        while not self._stopped:
            with self.lock:
                wake = self._step()
            timeout = max(0.0, wake - self.now())
            for key, _ in self._sel.select(timeout):
                reader = key.data
                if reader == self._woken:
                    reader(0)
                    continue
                with self.lock:
                    index, name = self._by_endpoint[id(reader.__self__)]
                    one = self._served[index]
                    data = reader(max(1, INPUT_BACKLOG - len(one.wire.ports[name].to_board)))
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
        if due == self._due[index]:
            return  # queued already
        self._due[index] = due
        if due < math.inf:
            heapq.heappush(self._queue, (due, index))
        if len(self._queue) > 4 * len(self._due) + 64:  # stale entries pile up: rebuild
            self._queue = [(d, i) for i, d in enumerate(self._due) if d < math.inf]
            heapq.heapify(self._queue)

    def _step(self) -> float:
        """Run every board that is due (only those: a heap orders them); when the next
        one is."""
        now = self.now()
        queue, ran = self._queue, []
        while queue and queue[0][0] <= now:
            due, index = heapq.heappop(queue)
            if due != self._due[index]:
                continue  # stale
            self._due[index] = math.nan
            if self.lateness is not None:
                self.lateness.append(now - due)
            one = self._served[index]
            one.pump(now)
            self._log_notes(one)
            one.throttle()
            ran.append(index)
        for index in ran:
            self._reschedule(index)
        return self._queue[0][0] if self._queue else math.inf

    def close(self) -> None:
        """Close every port, then the recording (what its decoders hold is written)."""
        for endpoint in self._endpoints:
            endpoint.close()
        self._sel.close()
        self._wake_read.close()
        self._wake_write.close()
        if self._recorder is not None:
            self._recorder.close()


def serve(
    make_endpoints: list[MakeEndpoint],
    boards: list[Board],
    *,
    pace: bool,
    log: Log,
    announce: Callable[[str], None],
    record: str | None = None,
    banner: str = "",
    directives: tuple[str, ...] = (),
    make_uart2: list[MakeEndpoint] | None = None,
) -> None:
    """Serve boards until interrupted (KeyboardInterrupt); `announce` gets each port line
    (`port: …`, then `uart2: …` when `make_uart2` serves the board's control port)."""
    server = BoardServer(
        make_endpoints,
        boards,
        pace=pace,
        log=log,
        record=record,
        directives=directives,
        make_uart2=make_uart2,
    )
    try:
        for i in range(len(boards)):
            urls = server.urls(i)
            announce(f"port: {urls[APP]}")
            if UART2 in urls:
                announce(f"uart2: {urls[UART2]}")
        if banner:
            log(banner)
        server.run()
    finally:
        server.close()


def switched_on(count: int, profile: Profile) -> list[float]:
    """When each of `count` boards served together is switched on: one by one over a
    record period, as cars are, so that their records do not all fall due at once."""
    period = profile.record_period_ms(len(app.encode(app.Velocity(0, 0, 0, 0)))) / 1000
    return [i * period / count for i in range(count)]


def run_board(
    *,
    use_pty: bool,
    link: str | None,
    listen: str | None,
    device: str | None,
    drive: str | None,
    flash: str | None,
    pace: bool,
    record: str | None,
    quiet: bool,
    count: int = 1,
    profile: str = "sheet",
    listen2: str | None = None,
    device2: str | None = None,
    baud: int | None = None,
) -> int:
    """The `appmode board` command: build the board(s) and serve until interrupted."""

    def log(text: str) -> None:
        if not quiet:
            print(f"board: {text}", file=sys.stderr, flush=True)

    def announce(text: str) -> None:
        print(text, flush=True)

    if count < 1:
        raise AppmodeError("--count must be at least 1")
    if count > 1 and (listen or device or link or flash or record or listen2 or device2):
        raise AppmodeError(
            "--count serves several boards on ptys: it cannot be combined "
            "with --listen, --port, --listen2, --port2, --link, --flash or --record"
        )
    if listen2 is not None and device2 is not None:
        raise AppmodeError("UART2 is served on one endpoint: give --listen2 or --port2, not both")
    make: MakeEndpoint
    if listen is not None:
        host, port = parse_listen(listen)
        make = partial(_tcp, host=host, port=port, baud=baud)
    elif device is not None:
        make = partial(_serial, device=device, baud=baud or BAUD)
    else:
        make = partial(_pty, link=link, baud=baud)
    make2: MakeEndpoint
    if listen2 is not None:
        host, port = parse_listen(listen2, "--listen2")
        make2 = partial(_tcp, host=host, port=port, baud=None)
    elif device2 is not None:
        make2 = partial(_serial, device=device2, baud=UART2_BAUD)
    else:
        make2 = partial(_pty, link=None, baud=UART2_BAUD if baud else None)
    kind = DriveType.from_cli_name(drive) if drive else None
    rules = profile_named(profile)
    rules.check(drive=kind is not None, flash=flash is not None)
    boards = [
        Board(open_store(flash), drive=kind, profile=rules, now=on)
        for on in switched_on(count, rules)
    ]
    body = (
        f"{boards[0].drive_type.cli_name} drive, flash {flash or 'in memory'}"
        if rules.drive_types
        else "no drive types, saves nothing"
    )
    banner = (
        f"simulated board{'s' if count > 1 else ''}, {rules.name} profile, {body}, "
        f"{'paced at the line rate' if pace else 'not paced'}"
    )
    if baud is not None:
        banner += f", APP port at {baud} bps"
    needs = [f"profile={profile}"] if rules is not SHEET else []
    needs += [f"drive={drive}"] if drive else []
    try:
        serve(
            [make] * count,
            boards,
            pace=pace,
            log=log,
            announce=announce,
            record=record,
            banner=banner,
            directives=(f"board {' '.join(needs)}",) if needs else (),
            make_uart2=[make2] * count,
        )
    except KeyboardInterrupt:
        log("stopped")
    finally:
        for board in boards:
            board.store.close()
    return 0


def _pty(sel: selectors.BaseSelector, log: Log, *, link: str | None, baud: int | None) -> Endpoint:
    return PtyEndpoint(sel, log, link, baud)


def _tcp(
    sel: selectors.BaseSelector, log: Log, *, host: str, port: int, baud: int | None
) -> Endpoint:
    return TcpEndpoint(sel, log, host, port, baud)


def _serial(sel: selectors.BaseSelector, log: Log, *, device: str, baud: int) -> Endpoint:
    return SerialEndpoint(sel, log, device, baud)
