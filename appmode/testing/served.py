"""A simulated board served on two pseudo-terminals from a thread of the caller's process,
for tests of host code that opens a serial port (the pytest plugin's `appmode_board`).

With `bluetooth=True` its APP port is a Bluetooth module behind the BlueZ stand-in, as
`appmode board --bluetooth` serves it. Its ports are otherwise what `appmode board`
serves: the APP port (UART3, 9600 bps) and the control port (UART2, 115200 bps), paced
like the real lines; on Windows, where there are no ptys, two loopback TCP ports
(`socket://127.0.0.1:N`); a WHEELTEC profile's board serves its chassis port too (115200
bps). Everything each port carries is recorded, as by `appmode board --record`.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from appmode.board.firmware import Board
from appmode.board.profiles import SHEET, profile_named
from appmode.board.store import open_store
from appmode.errors import AppmodeError, install_line
from appmode.line.faults import FaultSpec
from appmode.line.wire import APP, CHASSIS, UART2
from appmode.ports.endpoints import MakeEndpoint, PtyEndpoint, TcpEndpoint
from appmode.ports.serve import BoardServer
from appmode.protocol import params
from appmode.protocol.params import DriveType
from appmode.protocol.transcript import Transcript
from appmode.transcript.matcher import Check
from appmode.transcript.reading import read_transcript
from appmode.transcript.recorded import check_recorded

LOG_LINES = 1000
"""Lines of the board's own log kept (the newest)."""


@dataclass(frozen=True, slots=True)
class BoardState:
    """What the simulated board holds at one moment."""

    time: float
    """Seconds since the board was powered up."""
    velocity: tuple[int, int, int]
    """x, y, z as the A record's units (§3.1), whatever the profile's record shows."""
    attitude: tuple[int, int, int]
    """pitch, roll, yaw in degrees."""
    battery: int
    """Percent."""
    params: dict[str, int]
    """The nine parameters by name (docs/protocol.md §5), as in force."""
    page: str
    """`direction` or `button` (§4)."""
    drive_type: str
    """omni, mecanum, diff or diff-gyro."""
    driver: str
    """Who drives: `app` (the APP port's letters) or `uart2` (the control port took over,
    §8.3)."""

    @property
    def moving(self) -> bool:
        return any(self.velocity)


def _state(board: Board, boot: float, now: float) -> BoardState:
    v = board.vehicle
    return BoardState(
        time=now - boot,
        velocity=(round(v.vx), round(v.vy), round(v.vz)),
        attitude=(round(v.pitch), round(v.roll), round(v.heading) % 360),
        battery=v.battery,
        params={p.name: int(board.params[p.index]) for p in params.PARAMS},
        page=board.page.value,
        drive_type=board.drive_type.cli_name,
        driver=UART2 if board.uart2_control else APP,
    )


class ServedBoard:
    """One simulated board served on two ports until `close`.

    `port` and `uart2` are what a host opens (pyserial takes either: a pty path, or a
    `socket://` URL on Windows). `recording()` is everything the ports carried so far,
    `state` what the board holds now, `restart()` a power cycle keeping what was saved.
    """

    def __init__(
        self,
        folder: str | Path,
        *,
        profile: str = "sheet",
        drive: str | None = None,
        faults: str = "",
        pace: bool = True,
        flash: str | Path | None = None,
        home: str | Path | None = None,
        bluetooth: bool = False,
    ) -> None:
        folder = Path(folder)
        self.home = Path(home) if home is not None else None
        """Where `assert_conforms` looks for a relative transcript path it does not find
        from the current directory (the plugin: the test file's folder)."""
        folder.mkdir(parents=True, exist_ok=True)
        self.profile = profile_named(profile)
        try:
            self._drive = DriveType.from_cli_name(drive) if drive else None
            spec = FaultSpec.parse(faults)
        except ValueError as exc:
            raise AppmodeError(f"appmode_board: {exc}") from None
        self.profile.check(drive=self._drive is not None, flash=flash is not None)
        self.flash: Path | None = Path(flash) if flash is not None else None
        self.transcript_path = folder / "board.transcript"
        self.log: deque[str] = deque(maxlen=LOG_LINES)
        """The board's own log: what it received and what it did with it."""
        self._error: BaseException | None = None
        store = open_store(str(self.flash) if self.flash is not None else None)
        needs = [f"profile={profile}"] if self.profile is not SHEET else []
        needs += [f"drive={drive}"] if drive else []
        try:
            self._server = BoardServer(
                [_bluetooth() if bluetooth else _endpoint()],
                [Board(store, drive=self._drive, profile=self.profile)],
                pace=pace,
                log=self.log.append,
                record=str(self.transcript_path),
                directives=(f"board {' '.join(needs)}",) if needs else (),
                make_uart2=[_endpoint()],
                make_chassis=[_endpoint()] if self.profile.chassis is not None else None,
                faults=spec,
            )
        except BaseException:
            store.close()
            raise
        self._boot = 0.0
        urls = self._server.urls()
        self.port: str = urls[APP]
        """The APP port (UART3, 9600 bps): a path or URL that pyserial opens."""
        self.uart2: str = urls[UART2]
        """The control port (UART2, 115200 bps)."""
        self.chassis: str | None = urls.get(CHASSIS)
        """A WHEELTEC profile's chassis port (115200 bps), else None."""
        details = dict(line.split(": ", 1) for line in self._server.details())
        self.bus: str | None = details.get("bus")
        """With `bluetooth`: the BlueZ stand-in's bus, for DBUS_SYSTEM_BUS_ADDRESS."""
        self.ble: str | None = f"ble://{details['ble'].split()[0]}" if details else None
        """With `bluetooth`: the URL of the car's BLE module (HC-08)."""
        self.spp: str | None = f"bt://{details['spp']}" if details else None
        """With `bluetooth`: the URL of the car's paired classic module (HC-05)."""
        self._thread = threading.Thread(target=self._run, name="appmode board", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            self._server.run()
        except BaseException as exc:  # shown by the next call and at close
            self._error = exc

    def _check(self) -> None:
        if self._error is not None:
            raise AppmodeError(f"the simulated board stopped: {self._error!r}") from self._error

    @property
    def state(self) -> BoardState:
        """What the board holds now (its control loop run to this moment)."""
        self._check()
        return self._server.look(0, lambda b: _state(b, self._boot, self._server.now()))

    def wait_until(
        self, predicate: Callable[[BoardState], bool], timeout: float = 5.0, what: str = ""
    ) -> BoardState:
        """Poll `state` until `predicate` holds; AssertionError after `timeout` seconds,
        showing the last state."""
        __tracebackhide__ = True
        deadline = time.monotonic() + timeout
        while True:
            state = self.state
            if predicate(state):
                return state
            if time.monotonic() >= deadline:
                raise AssertionError(
                    f"the board did not reach {what or 'the state waited for'} in {timeout:g} s; "
                    f"it holds {state}"
                )
            time.sleep(0.01)

    def recording(self) -> Transcript:
        """Every unit both ports carried so far, as transcript entries (`>`, `<`, `2>`,
        `2<`), with the board's times."""
        self._check()
        with self._server.lock:  # no line is half written while it is read
            return read_transcript(self.transcript_path)

    def assert_conforms(self, expected: str | Path) -> None:
        """AssertionError, with `conform`'s message, unless the recording meets the
        expectations of the transcript `expected` (`appmode.transcript.recorded`). An
        expectation whose deadline has not yet come is waited for."""
        __tracebackhide__ = True
        path = Path(expected)
        if not path.is_absolute() and not path.exists() and self.home is not None:
            path = self.home / path
        transcript = read_transcript(path, name=str(expected))
        needs = Check(transcript).needs
        if needs.profile is not self.profile:
            raise AssertionError(
                f"{expected} is for the {needs.profile.name} profile; this board is "
                f"{self.profile.name} (@pytest.mark.appmode_board(profile="
                f"{needs.profile.name!r}))"
            )
        while True:  # an expectation whose deadline is still to come is waited for
            now = self._server.now()
            verdict = check_recorded(transcript, self.recording(), end=now)
            if verdict.wait is None or verdict.wait < now:
                break
            time.sleep(verdict.wait - now + 0.01)
        if verdict.failure is not None:
            raise AssertionError(verdict.failure)

    def restart(self) -> None:
        """Power-cycle the board: same ports, same flash (what was saved is kept), the
        board's clock from 0 again; what was on its lines is lost."""
        self._check()

        def make(old: Board, now: float) -> Board:
            self._boot = now
            return Board(old.store, drive=self._drive, profile=self.profile, now=now)

        self._server.restart(0, make)

    def close(self) -> None:
        """Stop serving; the ports and the recording are closed. Raises what stopped the
        board if it failed while serving."""
        if self._thread.is_alive():
            self._server.stop()
            self._thread.join(5)
        board = self._server.look(0, lambda b: b)
        with contextlib.suppress(AppmodeError):
            self._server.close()
        board.store.close()
        self._check()

    def __enter__(self) -> ServedBoard:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _bluetooth() -> MakeEndpoint:
    """The BlueZ stand-in on a private bus (Linux; needs dbus-daemon and dbus-fast)."""
    try:
        from appmode.bluetooth.standin.endpoint import BluetoothEndpoint
    except ImportError:
        raise AppmodeError(
            f"appmode_ble_board needs the bluetooth extra: {install_line('bluetooth')}"
        ) from None
    return BluetoothEndpoint


def _endpoint() -> MakeEndpoint:
    """A pty; on Windows, which has none, a loopback TCP port."""
    if sys.platform == "win32":
        return partial(TcpEndpoint, host="127.0.0.1", port=0)
    return PtyEndpoint
