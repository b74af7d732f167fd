"""`appmode tap`: sit between an app and a board, forwarding and recording both ways.

Two threads each read one side and write to the other; the recorder hears both. The app
side may be `pty` — a new pseudo-terminal for the app to open (its path is printed) — or
`advertise[:NAME]`: appmode advertised as the car's Bluetooth module, for the phone's app
to connect to. When a side leaves, the transcript says which; on the way out the board
gets `Z` (after closing any frame the app left open): the app can no longer stop it.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from typing import Protocol

import serial

from appmode.bluetooth.advertise.admission import ANY_PHONE, Admission
from appmode.errors import AppmodeError, install_line
from appmode.line.pacing import Ahead
from appmode.ports.recording import open_recorder
from appmode.ports.urls import LinkLeft, new_pty, open_link
from appmode.protocol.recorder import Recorder
from appmode.protocol.session_end import SessionEnd

READ_TIMEOUT = 0.05
CHUNK = 64
"""Bytes forwarded at once: the longest a stop waits behind them (67 ms at 9600 bps)."""
JOIN = 5.0
"""Seconds a forwarding thread has to finish its chunk once the tap stops."""


class Stream(Protocol):
    """What tap forwards between: a pyserial port or a new pty."""

    @property
    def in_waiting(self) -> int: ...

    def read(self, size: int = 1) -> bytes: ...

    def write(self, data: bytes) -> int | None: ...

    def close(self) -> None: ...


def _read(port: Stream) -> bytes:
    return port.read(max(1, port.in_waiting))


ADVERTISE = "advertise"
"""The app side that is appmode advertised as a Bluetooth module (`advertise:NAME`)."""
ADVERTISED_NAME = "HC-08"


def _app_side(app_url: str, nus: bool, quiet: bool, admission: Admission | None) -> Stream:
    """The app's side, open; its address printed as `port: …` when tap made it."""
    if app_url == "pty":
        pty_port = new_pty()
        print(f"port: {pty_port.path}", flush=True)
        return pty_port
    word, _, name = app_url.partition(":")
    if word != ADVERTISE:
        link: Stream = open_link(app_url, timeout=READ_TIMEOUT)
        return link
    from appmode.bluetooth.advertise.module_name import name_problem
    from appmode.bluetooth.availability import unsupported

    name = name or ADVERTISED_NAME
    if (why := name_problem(name) or unsupported()) is not None:
        raise AppmodeError(f"tap {app_url}: {why}")
    try:
        from appmode.bluetooth.advertise.port import AdvertisedPort
        from appmode.bluetooth.uuids import UART_SERVICES
    except ImportError:
        raise AppmodeError(
            f"tap {app_url} needs the bluetooth extra: {install_line('bluetooth')}"
        ) from None

    def log(text: str) -> None:
        if not quiet:
            print(f"tap: {text}", file=sys.stderr, flush=True)

    admitted = admission or ANY_PHONE
    port = AdvertisedPort(name, UART_SERVICES[1 if nus else 0], log, READ_TIMEOUT, admitted)
    if (warning := admitted.warning(name)) is not None:  # said once it is on the air
        print(f"tap: {warning}", file=sys.stderr, flush=True)
    print(f"port: ble://{name}", flush=True)
    return port


def run_tap(
    app_url: str,
    board_url: str,
    record: str,
    quiet: bool,
    nus: bool = False,
    admission: Admission | None = None,
) -> int:
    """Forward until interrupted or a side leaves, recording both directions; an
    advertised app side takes the phones `admission` admits (default: any)."""
    if (nus or admission) and not app_url.startswith(ADVERTISE):
        raise AppmodeError(
            "--nus, --allow and --secure are for an advertised app side: tap advertise[:NAME] …"
        )
    app = _app_side(app_url, nus, quiet, admission)
    try:
        board = open_link(board_url, timeout=READ_TIMEOUT)
    except BaseException:
        app.close()
        raise
    try:
        recorder = open_recorder(record)
    except BaseException:
        board.close()
        app.close()
        raise
    recorder.note(f"tap: {app_url} <-> {board_url}", 0.0)
    tap = Tap(app, board, recorder)
    if not quiet:
        print(
            f"tap: {app_url} <-> {board_url}, recording to {record} (Ctrl-C to stop)",
            file=sys.stderr,
            flush=True,
        )
    tap.run()
    if not quiet:
        counts = tap.counts
        print(
            f"tap: {counts['>']} bytes app->board, {counts['<']} bytes board->app", file=sys.stderr
        )
    if tap.left and not quiet:
        print(f"tap: {tap.left}; the board got Z", file=sys.stderr)
    for error in tap.errors:
        print(f"tap: stopped: {error}", file=sys.stderr)
    return 1 if tap.errors else 0


class Tap:
    """Two ports forwarded to each other, each way in its own thread, both recorded; at
    the end the board gets the stop the app can no longer send."""

    def __init__(self, app: Stream, board: Stream, recorder: Recorder) -> None:
        self.app, self.board, self.recorder = app, board, recorder
        self.counts = {">": 0, "<": 0}
        self.errors: list[str] = []
        self.left = ""
        """Which side left, and why (a phone that disconnected: not an error)."""
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._origin = time.monotonic()
        self._end = SessionEnd()  # what the app sent: its frame may be open when it leaves

    def run(self) -> None:
        """Forward until interrupted (Ctrl-C) or a side fails; then stop the car and close."""
        threads = [
            threading.Thread(
                target=self._forward,
                args=(self.app, self.board, ">"),
                name="app side",
                daemon=True,
            ),
            threading.Thread(
                target=self._forward,
                args=(self.board, self.app, "<"),
                name="board side",
                daemon=True,
            ),
        ]
        for thread in threads:
            thread.start()
        try:
            while not self._stop.is_set():
                self._stop.wait(0.2)
        except KeyboardInterrupt:
            pass
        finally:
            self._stop.set()
            for thread in threads:  # forwarding ends first: the stop is the last on the wire
                thread.join(JOIN)
            stuck = [t.name for t in threads if t.is_alive()]
            with contextlib.suppress(serial.SerialException, OSError):
                self.board.write(self._end.stop)  # the app can no longer stop the car
                self.recorder(">", time.monotonic() - self._origin, self._end.stop)
            if stuck:
                stuck_text = ", ".join(stuck)
                self.errors.append(
                    f"{stuck_text} still writing after {JOIN:g} s: its port is stuck"
                )
            self.board.close()
            self.app.close()
            self.recorder.close()

    def _forward(self, src: Stream, dst: Stream, direction: str) -> None:
        """Copy src to dst, a chunk at a time and no faster than dst's line carries
        it, until stopped: at the end nothing is still on its way to the board."""
        ahead = Ahead(getattr(dst, "baudrate", None), CHUNK)
        stop = self._stop
        try:
            while not stop.is_set():
                data = _read(src)
                for start in range(0, len(data), CHUNK):
                    stop.wait(ahead.delay(time.monotonic()))
                    if stop.is_set():
                        return  # the rest of what the app sent is not forwarded
                    chunk = data[start : start + CHUNK]
                    dst.write(chunk)
                    ahead.wrote(len(chunk), time.monotonic())
                    with self._lock:
                        self.counts[direction] += len(chunk)
                        if direction == ">":
                            self._end.sent(chunk)
                        self.recorder(direction, time.monotonic() - self._origin, chunk)
        except Exception as exc:  # a side left, a failed recording: end the tap, say why
            name = "app side" if direction == ">" else "board side"
            if not isinstance(exc, AppmodeError):  # a side's end: the transcript says it
                with self._lock, contextlib.suppress(AppmodeError):
                    when = time.monotonic() - self._origin
                    self.recorder.note(f"the {name} left at {when:.3f} s: {exc}", when)
            if isinstance(exc, LinkLeft):
                self.left = f"the {name} left: {exc}"
            else:
                self.errors.append(f"{name}: {exc}")
            stop.set()
