"""`sim://`: the simulated board in-process, as a pyserial port.

`sim://?drive=mecanum&flash=board.json&pace=0` — options: `profile` (sheet, the
default, or minibalance: docs/protocol.md §13), `drive` (omni, mecanum, diff, diff-gyro;
default: what the flash holds, else omni), `flash` (a JSON parameter file; default: in
memory), `pace` (1: bytes move at the real 9600-bps rate, the default; 0: instantly),
`baud`, `faults` (a faulty link both ways, see line/faults.py), `port` (app, the
default: the APP port, UART3 at 9600 bps; uart2: the control port at 115200 bps,
docs/protocol.md §8) and `share` (a name: every port opened with the same name in one
process is a port of one board, so `sim://?share=car` and `sim://?share=car&port=uart2`
are its two ports). There is no thread: the board runs whenever a port is used.
"""

from __future__ import annotations

import math
import random
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import serial
from serial import SerialException

from appmode.board.firmware import Board
from appmode.board.profiles import profile_named
from appmode.board.store import open_store
from appmode.errors import AppmodeError
from appmode.line.faults import FaultSpec, FaultyLine
from appmode.line.pacing import Line
from appmode.line.wire import APP, CHASSIS, UART2, UART2_BAUD, Wire
from appmode.ports.modemless import Modemless
from appmode.ports.target import SIM_USAGE, Target
from appmode.ports.urls import port_target
from appmode.protocol import params
from appmode.protocol.params import DriveType
from appmode.protocol.transcript import TIME_DIGITS

BOARD_OPTIONS = ("profile", "drive", "flash", "pace")
"""The options that make the board: ports that share one must agree on them."""
WRITE_BUFFER = 4096
"""Bytes a write may queue ahead of the line, like an OS serial buffer; then it blocks."""
MIN_BAUD, MAX_BAUD = 300, 4_000_000
"""Paced rates a simulated line takes: below 300 bps closing (which waits for what is
queued to go out) could take minutes."""


def _on_grid(seconds: float) -> float:
    """A board time on the grid of a transcript's times (0.1 ms, floored)."""
    grid: int = 10**TIME_DIGITS
    return math.floor(seconds * grid) / grid


@dataclass
class Shared:
    """A board and its wire, used by every port opened on it."""

    wire: Wire
    origin: float
    options: tuple[tuple[str, str], ...]
    lock: threading.RLock = field(default_factory=threading.RLock)
    open_ports: set[str] = field(default_factory=set)


_SHARED: dict[str, Shared] = {}
_SHARED_LOCK = threading.Lock()


def _flag(name: str, text: str) -> bool:
    if text.lower() in ("1", "true", "yes", "on"):
        return True
    if text.lower() in ("0", "false", "no", "off"):
        return False
    raise SerialException(f"sim:// option {name}={text!r}: use 1 or 0")


class SimSerial(Modemless):
    """A pyserial port with the simulated board at the other end."""

    is_open: bool

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._wire: Wire | None = None
        self._shared: Shared | None = None
        self._share_name: str | None = None
        self._side = APP
        self._faults: tuple[FaultyLine, FaultyLine] | None = None
        self._rx = bytearray()
        self._rx_times: deque[list[float]] = deque()  # [board time, count] runs of _rx
        self._pumped = 0.0
        self._origin = 0.0
        self.written_at = 0.0
        """Board time at which the last write went on the line, on the grid of a
        transcript's times (0.1 ms, floored): a recording of a simulated session stamps
        a write with it, and so replays exactly on virtual time."""
        self.read_runs: list[tuple[float, int]] = []
        """The bytes the last read returned, as runs of (board time they arrived, count)."""
        self.board: Board | None = None
        self.target: Target | None = None
        """The board to open, parsed once (`ports.urls.port_target`)."""
        super().__init__(*args, **kwargs)

    def open(self) -> None:
        if self.is_open:
            raise SerialException("port is already open")
        if self._port is None:
            raise SerialException("port must be configured before it can be used")
        target = port_target(self)
        if not target.simulated:
            raise SerialException(f"expected {SIM_USAGE}, not {target.url!r}")
        options, side = target.sim, target.sim_port
        try:
            drive = DriveType.from_cli_name(options["drive"]) if "drive" in options else None
        except ValueError as exc:
            raise SerialException(f"sim:// option drive: {exc}") from None
        try:
            profile = profile_named(options.get("profile", "sheet"))
            profile.check(drive=drive is not None, flash="flash" in options)
        except AppmodeError as exc:
            raise SerialException(f"sim:// option profile: {exc}") from None
        if side == CHASSIS and profile.chassis is None:
            raise SerialException(
                f"sim:// port=chassis: the {profile.name} profile's board has no chassis "
                "port (profile=wheeltec-mec, wheeltec-akm or wheeltec-diff has)"
            )
        if "baud" in options:
            baud = params.whole(options["baud"])
            if baud is None or not MIN_BAUD <= baud <= MAX_BAUD:
                raise SerialException(
                    f"sim:// option baud={options['baud']!r}: use a number in {MIN_BAUD}–{MAX_BAUD}"
                )
            self._baudrate = baud
        elif side in (UART2, CHASSIS):
            self._baudrate = UART2_BAUD
        pace = _flag("pace", options.get("pace", "1"))
        try:
            spec = FaultSpec.parse(options.get("faults", ""))
        except ValueError as exc:
            raise SerialException(f"sim:// option faults: {exc}") from None
        rng = random.Random(spec.seed)
        self._faults = (FaultyLine(spec, rng), FaultyLine(spec, rng)) if spec.active else None
        name = options.get("share")
        made = tuple((key, options[key]) for key in BOARD_OPTIONS if key in options)
        with _SHARED_LOCK:
            shared = _SHARED.get(name) if name is not None else None
            if shared is None:
                try:  # the flash is opened last: nothing after it can fail and leave it locked
                    store = open_store(options.get("flash"))
                except AppmodeError as exc:
                    raise SerialException(str(exc)) from None
                board = Board(store, drive=drive, profile=profile)
                shared = Shared(Wire(board, None, None, None), time.monotonic(), made)
                if name is not None:
                    _SHARED[name] = shared
            elif shared.options != made:
                raise SerialException(
                    f"sim:// share={name}: its board is open with "
                    f"{dict(shared.options) or 'no options'}; open this port with the same "
                    f"{', '.join(BOARD_OPTIONS)}"
                )
            if side in shared.open_ports:
                raise SerialException(f"sim:// share={name}: its {side} port is already open")
            shared.open_ports.add(side)
        baud = self._baudrate if pace else None
        port = shared.wire.ports[side]
        port.to_board, port.to_host = Line(baud), Line(baud)
        self._shared, self._share_name, self._side = shared, name, side
        self._wire = shared.wire
        self.board = shared.wire.board
        self._clear_rx()
        self._origin = shared.origin
        self.is_open = True

    def close(self) -> None:
        self.is_open = False
        self._wire = None
        shared, self._shared = self._shared, None
        if shared is None:
            return
        with _SHARED_LOCK:
            shared.open_ports.discard(self._side)
            if shared.open_ports:
                return
            if self._share_name is not None:
                _SHARED.pop(self._share_name, None)
        shared.wire.board.store.close()

    def _reconfigure_port(self, force_update: bool = False) -> None:
        """Settings change nothing in the simulation (the line rate is fixed at open)."""

    def _now(self) -> float:
        return time.monotonic() - self._origin

    @property
    def clock_origin(self) -> float:
        """`time.monotonic()` at the board's power-up: its clock's zero."""
        return float(self._origin)

    @property
    def heard_until(self) -> tuple[float, bool]:
        """Up to which board time every byte that arrived has been read: (time, whether
        a byte at that very time has been read too). Writes before it may be told after
        what was read, in time order."""
        try:  # the reader's thread may take the last run meanwhile
            return _on_grid(self._rx_times[0][0]), False
        except IndexError:
            return _on_grid(self._pumped), True

    def _pump(self) -> Wire:
        wire, shared = self._wire, self._shared
        if not self.is_open or wire is None or shared is None:
            raise serial.PortNotOpenError()
        side = self._side
        with shared.lock:
            now = self._now()
            if self._faults is None:
                for when, chunk in wire.pump_timed(now, side):
                    self._arrived(when, chunk)
            else:
                to_board, to_host = self._faults
                wire.write(to_board.take(now), now, side)
                to_host.push(wire.pump(now, side), now)
                self._arrived(now, to_host.take(now))  # a faulty line's: when taken
            self._pumped = now
        return wire

    def _arrived(self, when: float, chunk: bytes) -> None:
        if not chunk:
            return
        self._rx += chunk
        if self._rx_times and self._rx_times[-1][0] == when:
            self._rx_times[-1][1] += len(chunk)
        else:
            self._rx_times.append([when, len(chunk)])

    def _clear_rx(self) -> None:
        self._rx.clear()
        self._rx_times.clear()

    def _next_wakeup(self, wire: Wire) -> float:
        assert self._shared is not None
        with self._shared.lock:
            times = [wire.next_wakeup()]
        if self._faults is not None:
            times += [t for line in self._faults if (t := line.next_due()) is not None]
        return min(times)

    def _line(self, wire: Wire) -> Line:
        return wire.ports[self._side].to_board

    @property
    def in_waiting(self) -> int:
        self._pump()
        return len(self._rx)

    @property
    def out_waiting(self) -> int:
        return len(self._line(self._pump()))

    def read(self, size: int = 1) -> bytes:
        wire = self._pump()
        deadline = None if self._timeout is None else self._now() + self._timeout
        while len(self._rx) < size:
            now = self._now()
            if deadline is not None and now >= deadline:
                break
            wake = self._next_wakeup(wire)
            if deadline is not None:
                wake = min(wake, deadline)
            time.sleep(max(0.0, wake - now))
            wire = self._pump()
        data = bytes(self._rx[:size])
        del self._rx[:size]
        self.read_runs = []
        left = len(data)
        while left:  # the arrival times of what was read go with it
            run = self._rx_times[0]
            taken = min(left, int(run[1]))
            self.read_runs.append((_on_grid(run[0]), taken))
            run[1] -= taken
            left -= taken
            if not run[1]:
                self._rx_times.popleft()
        return data

    def write(self, data: bytes) -> int:
        wire = self._pump()
        payload = serial.to_bytes(data)
        while len(self._line(wire)) > WRITE_BUFFER:  # the line is slower than the writer
            time.sleep(max(0.0, self._next_wakeup(wire) - self._now()))
            wire = self._pump()
        assert self._shared is not None
        with self._shared.lock:
            self._pump()  # what arrived before the write is in hand (`heard_until`)
            self.written_at = now = _on_grid(self._pumped)
            if self._faults is None:
                wire.write(payload, now, self._side)
            else:
                self._faults[0].push(payload, now)
        return len(payload)

    def flush(self) -> None:
        wire = self._pump()
        while self._line(wire).next_due() is not None or (
            self._faults is not None and self._faults[0].next_due() is not None
        ):
            time.sleep(max(0.0, self._next_wakeup(wire) - self._now()))
            wire = self._pump()

    def reset_input_buffer(self) -> None:
        self._pump()
        self._clear_rx()

    def reset_output_buffer(self) -> None:
        """Bytes already on the simulated line cannot be called back."""
