"""A host's side of a link, whatever it speaks: open a URL, write, read, notice a lost
link and reopen the same URL every RETRY seconds, saying so each time (LinkStatus).

Thread-free: the protocol hosts (`client.Host` on the APP port, `control_client.
ControlHost` on UART2) build on it and decode what `_read_once` brings.
"""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Callable, Iterator
from types import TracebackType
from typing import Any, Generic, TypeVar

import serial
from serial.urlhandler import protocol_socket

from appmode.errors import AppmodeError
from appmode.host import signals
from appmode.host.events import LinkStatus
from appmode.line.pacing import Ahead
from appmode.line.wire import Tap
from appmode.ports.remote import WriteRefused
from appmode.ports.target import Target, as_target

Opener = Callable[[Target], serial.SerialBase]
"""Opens a port by its Target (`ports.urls.open_link`, with options bound)."""
RETRY = 0.5
CHUNK = 64
"""Bytes written at once: 67 ms at 9600 bps, the longest an ending signal waits."""
STEP = 0.001
"""Seconds between looks at the port while waiting less than its read timeout."""

E = TypeVar("E")
R = TypeVar("R")
L = TypeVar("L", bound="Link[Any]")


UNDELIVERED = "the final stop was not delivered: the car may still be moving"
"""Said when a session ends with its link down and the car last told to move: no host
can stop it now (the firmware has no time-out)."""
LINGER = 0.5
"""Seconds a TCP link waits at its end for the other side to take the last bytes."""


def _end_tcp(port: serial.SerialBase) -> None:
    """End a TCP link (pyserial's socket://) gently: say the end, then read what is still
    coming until the other side closes. Closing with unread bytes resets the
    connection: a board whose next write then fails may drop it before it has read
    the final stop."""
    sock = getattr(port, "_socket", None)
    if not isinstance(port, protocol_socket.Serial) or not isinstance(sock, socket.socket):
        return
    with contextlib.suppress(OSError):
        sock.shutdown(socket.SHUT_WR)
        sock.settimeout(LINGER)
        deadline = time.monotonic() + LINGER
        while sock.recv(4096) and time.monotonic() < deadline:
            pass


class LinkLost(AppmodeError):
    """The link is down; the host is trying to get it back."""


class Refused(AppmodeError):
    """The far side of the link refused the bytes (a shared car another client drives):
    nothing was sent; the link stays up."""


class Cut(AppmodeError):
    """A stop came while the bytes were going out: the rest was not sent (`send`'s
    `still`)."""


UNHEARD = 256
"""Writes held for the reads to catch up with them at most; past that a host that never
reads has them told at once (memory stays bounded; its recording's order is the writes')."""


class Link(Generic[E]):
    """One open port and its session clock; `sent`/`received` name the tap directions."""

    sent = ">"
    received = "<"
    stop_on_close = True
    stopped_far = False
    """The link was lost after the far end stopped the car (a share that ended)."""
    proves_return = False
    """A reopened link is back only once the protocol has decoded the board's output
    (`_proven`): a path left by a board that died (a pty's) may now lead to another
    program's port."""

    def __init__(
        self,
        url: Target | str,
        tap: Tap | None,
        opener: Opener,
    ) -> None:
        self.target = as_target(url)
        self.url = self.target.url
        self.tap = tap
        self._opener = opener
        self._port: serial.SerialBase | None = opener(self.target)
        self._writing = threading.RLock()  # the stop guard may write from its thread
        self._stop_wanted = threading.Event()
        """A stop waits to be written: a write's pacing gives way at once."""
        self._tapping = threading.Lock()
        self._unheard: list[tuple[float, bytes]] = []  # sends told once reads catch up
        # after opening: an in-process sim:// board booted just now, and its clock is ours
        # (a shared car's began when its share did: this session's time starts now)
        board_origin = getattr(self._port, "clock_origin", None) if self.target.simulated else None
        self._origin = time.monotonic() if board_origin is None else float(board_origin)
        self._lost_at = 0.0
        self._ahead: Ahead | None = None  # the line's rate, known once the port is open
        self._pending: list[E | LinkStatus] = []
        self._proven = True  # the port opened is the board's, or has shown it is
        self._heard = False  # bytes have come since the port was (re)opened
        self.refused: str | None = None
        """Why the link drops at once, when the far end closes it before a byte: a TCP
        board serving another client."""
        self.refusals = 0
        """Times in a row the far end closed the link before a byte."""
        self.latency: float | None = None
        """Milliseconds the last write took to be acknowledged, on a port that says (a
        car shared over the network: its host acknowledges what it wrote)."""

    def now(self) -> float:
        """Seconds since the session started."""
        return time.monotonic() - self._origin

    @property
    def origin(self) -> float:
        """`time.monotonic()` at this link's clock zero (`now()` counts from it)."""
        return self._origin

    @property
    def connected(self) -> bool:
        """The port is open, and (after a reopening) has shown it is the board's."""
        return self._port is not None and self._proven

    @property
    def link(self) -> serial.SerialBase | None:
        """The open port (None while the link is down)."""
        return self._port

    def _on_lost(self) -> None:
        """What the protocol forgets when the link drops (a decoder's partial bytes)."""

    def _lost(self, exc: Exception) -> None:
        self.stopped_far = getattr(self._port, "host_stopped_car", False) is True
        if self._port is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                self._port.close()
        self._port = None
        self._lost_at = self.now()
        self._on_lost()
        if not self._heard and self.target.network:
            self.refused = (
                f"{self.url} closed the connection before the board sent anything: a TCP "
                "board serves one client at a time; close the other client and retry"
            )
            self.refusals += 1
            exc = OSError(self.refused)
        if self._proven:  # a reopened port that never showed the board: already said
            then = (
                "a pty that is gone never comes back (its number may be another program's "
                "terminal next): not reopened; start again on the board's new port"
                if self.target.numbered_pty
                else "retrying"
            )
            self._pending.append(LinkStatus(False, f"link to {self.url} lost ({exc}); {then}"))
        self._tell_all_sent()  # last: a recording that fails here cannot undo the above

    def _reconnect(self) -> None:
        if self.target.numbered_pty or self.now() - self._lost_at < RETRY:
            return
        self._lost_at = self.now()
        try:
            self._port = self._opener(self.target)
        except AppmodeError:
            return
        self._heard = False
        if not self.proves_return:
            self._stop_after_outage()
            self._pending.append(LinkStatus(True, f"link to {self.url} is back"))
            return
        if self._proven:  # said once an outage
            self._pending.append(
                LinkStatus(False, f"{self.url} opens again; waiting for the board's output")
            )
        self._proven = False

    def _stop_after_outage(self) -> None:
        """The first thing a reopened link sends is the stop: the car kept its last
        command while the link was down (the firmware has no time-out)."""
        if self.stop_on_close and self._port is not None:
            with self._writing, contextlib.suppress(LinkLost, Refused):
                self._write_chunk(self._stop())

    def _proven_by_output(self) -> None:
        """The protocol decoded the board's output: a reopened link is back."""
        if not self._proven:
            self._proven = True
            self._stop_after_outage()
            self._pending.append(LinkStatus(True, f"link to {self.url} is back"))

    def _write(self, data: bytes, still: Callable[[], bool] | None = None) -> None:
        """Write bytes to the board, CHUNK at a time, each tapped and followed (`_sent`)
        as it leaves; LinkLost if the link is down; Cut when `still()` turns false
        before a chunk (a stop came: it goes out next). An ending signal waits for the
        chunk under way: what the session end knows is what really left."""
        with self._writing:
            if self._port is None:
                self._reconnect()
            if self._port is None:
                raise LinkLost(f"link to {self.url} is down; not sent: {data!r}")
            for start in range(0, len(data), CHUNK):
                self._pace(min(CHUNK, len(data) - start))
                if still is not None and not still():
                    raise Cut(f"not all sent to {self.url}: a stop came ({start} bytes sent)")
                self._write_chunk(data[start : start + CHUNK])

    def _write_chunk(self, chunk: bytes) -> None:
        with signals.atomic():
            port = self._port
            if port is None:  # lost at the last chunk
                raise LinkLost(f"link to {self.url} lost while sending")
            try:
                port.write(chunk)
            except WriteRefused as exc:
                raise Refused(f"not sent to {self.url}: {exc}") from None
            except (serial.SerialException, OSError) as exc:
                self._lost(exc)
                raise LinkLost(f"link to {self.url} lost while sending: {exc}") from None
            self.latency = getattr(port, "latency", None)
            if self.tap is not None:
                self._tap_sent(port, chunk)
            self._sent(chunk)

    def _tap_sent(self, port: serial.SerialBase, chunk: bytes) -> None:
        """Tell the tap what was just written. A port that keeps the board's clock
        (sim://) says when the board took it, and when what was read arrived: the tap
        hears both in time order (a recording of it replays exactly on virtual time, even
        when this host read late), so a write waits for the reads to catch up with it."""
        at = getattr(port, "written_at", None)
        assert self.tap is not None
        if at is None or not hasattr(port, "read_runs"):
            self.tap(self.sent, self.now(), chunk)
            return
        offset = self._board_offset(port)
        with self._tapping:
            self._unheard.append((float(at) + offset, chunk))
            until, including = port.heard_until  # nothing unread came before it: now
            if len(self._unheard) > UNHEARD:  # a host that never reads: told as sent
                until, including = float("inf"), True
            self._tell_sent(until + offset, including)

    def _tap_received(self, port: serial.SerialBase, data: bytes) -> None:
        """Tell the tap what was just read (empty: nothing, but the reads caught up)."""
        assert self.tap is not None
        runs = getattr(port, "read_runs", None)
        if runs is None:
            if data:
                self.tap(self.received, self.now(), data)
            return
        offset = self._board_offset(port)
        with self._tapping:
            start = 0
            for when, count in runs if data else ():
                self._tell_sent(when + offset, including=False)  # what came first goes first
                self.tap(self.received, when + offset, data[start : start + count])
                start += count
            until, including = port.heard_until
            self._tell_sent(until + offset, including)

    def _tell_sent(self, until: float, including: bool) -> None:
        """Tell the tap the held writes before `until` (and at it, if `including`)."""
        assert self.tap is not None
        while self._unheard and (
            self._unheard[0][0] < until or (including and self._unheard[0][0] == until)
        ):
            at, chunk = self._unheard.pop(0)
            self.tap(self.sent, at, chunk)

    def _tell_all_sent(self) -> None:
        if self.tap is not None:
            with self._tapping:
                self._tell_sent(float("inf"), including=True)

    def _board_offset(self, port: serial.SerialBase) -> float:
        """A board time of `port` as this session's time."""
        return float(port.clock_origin) - self._origin

    def _pace(self, size: int) -> None:
        """Hand the OS no more than a chunk ahead of the line's rate: what it holds would
        reach the board before the stop that ends the session (a pty takes kilobytes:
        seconds of driving at 9600 bps)."""
        if self._ahead is None:
            baud = getattr(self._port, "baudrate", None)
            self._ahead = Ahead(baud if isinstance(baud, int) else None, CHUNK)
        wait = self._ahead.delay(self.now())
        if wait:
            self._stop_wanted.wait(wait)  # a stop waiting cuts the wait short
        self._ahead.wrote(size, self.now())

    def _sent(self, data: bytes) -> None:
        """Follow bytes that have left (the protocol's session end, its counters)."""

    def _read_bytes(self, block: bool) -> bytes:
        """What the port has (waiting for the first byte up to its timeout if `block`),
        tapped; b"" when nothing came or the link is down."""
        if self._port is None:
            self._reconnect()
        if self._port is None:
            return b""
        try:
            waiting = self._port.in_waiting
            data: bytes = self._port.read(max(1, waiting)) if block or waiting else b""
        except (serial.SerialException, OSError) as exc:
            self._lost(exc)
            return b""
        if data:
            self._heard, self.refused, self.refusals = True, None, 0
        if self.tap is not None:
            self._tap_received(self._port, data)
        return data

    def _read_once(self, block: bool) -> list[E | LinkStatus]:
        raise NotImplementedError

    def poll(self, timeout: float) -> list[E | LinkStatus]:
        """What arrives within `timeout` seconds: returns as soon as something does, and
        never after the deadline."""
        return self._read_until(timeout, self._read_once, bool)

    def _read_until(
        self,
        timeout: float,
        read: Callable[[bool], list[R]],
        enough: Callable[[list[R]], bool],
    ) -> list[R]:
        """Call `read` until what it returns is `enough` or `timeout` passes; its last
        return. A wait longer than the port's read timeout blocks in the port; a
        shorter one looks every STEP seconds, so a caller with something to send at the
        deadline (conform, replay) is not held up by the read."""
        deadline = self.now() + timeout
        while True:
            wait = None if self._port is None else self._port.timeout
            block = wait is not None and deadline - self.now() >= wait
            events = read(block)
            left = deadline - self.now()
            if enough(events) or left <= 0:
                return events
            if not block:
                time.sleep(min(RETRY / 5 if self._port is None else STEP, left))

    def poll_nowait(self) -> list[E | LinkStatus]:
        """What has arrived, without waiting."""
        return self._read_once(block=False)

    def events(self, duration: float | None = None) -> Iterator[E | LinkStatus]:
        """What arrives, as it arrives, for `duration` seconds (forever: None)."""
        end = None if duration is None else self.now() + duration
        while end is None or self.now() < end:
            step = 0.2 if end is None else max(0.0, min(0.2, end - self.now()))
            yield from self.poll(step)

    def _take_pending(self) -> list[E | LinkStatus]:
        events, self._pending = self._pending, []
        return events

    def send(self, data: bytes, still: Callable[[], bool] | None = None) -> None:
        """Write bytes to the board; LinkLost if the link is down. With `still`, a stop
        pre-empts them: checked before each chunk, it turns false when one is sent
        (Cut: the rest is not)."""
        self._write(data, still)

    def _stop(self) -> bytes:
        """The bytes that leave the car stopped, sent last when the session closes."""
        raise NotImplementedError

    def send_stop(self) -> bytes | None:
        """Send the port's stop now, as `close` ends with it (what was sent decides
        it): the bytes sent, or None when the link is down."""
        self._stop_wanted.set()  # a write under way gives way after its chunk
        try:
            with self._writing:
                self._stop_wanted.clear()
                stop = self._stop()  # what was sent decides it: after that write
                self.send(stop)
        except (LinkLost, Refused):
            return None
        return stop

    def close(self) -> bytes | None:
        """Stop the car (`_stop()` is the last thing sent), check that it took where the
        protocol can (`_confirm`: AppmodeError if it did not), then close the port.
        Returns the bytes of that stop, or None if the link was down. A passive host
        (`stop_on_close` False, a monitor) sends nothing. An ending signal waits until
        the stop has been written."""
        with signals.atomic():
            if self._port is None:
                return None
            stop = b""
            try:
                if self.stop_on_close:
                    self._before_stop()
                    stop = self._stop()
                    self.send(stop)
            except LinkLost:
                return self.close()  # the port is gone: nothing was sent
            except Refused:
                stop = b""  # another client drives: not this one's to stop
            except AppmodeError:
                pass  # written; only its recording failed, which must not keep it open
        try:
            if stop:
                self._confirm()
        finally:
            if self._port is not None:
                with contextlib.suppress(serial.SerialException, OSError):
                    self._port.flush()
                _end_tcp(self._port)
                self._port.close()
                self._port = None
            with contextlib.suppress(AppmodeError):  # only its recording failed, as above
                self._tell_all_sent()
        return stop

    def _before_stop(self) -> None:
        """Just before the stop is sent (a host that checks it reads what is waiting)."""

    def _confirm(self) -> None:
        """After the stop: AppmodeError if the board shows it did not take."""

    def __enter__(self: L) -> L:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
