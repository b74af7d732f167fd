"""Where a served board's port meets its client: a new pseudo-terminal, a TCP listener
(one client at a time), or a real serial port. Each registers itself with the server's
selector, reads what its client sends, and writes what the board sends — dropping, as a
UART does, what nobody reads."""

from __future__ import annotations

import contextlib
import errno
import os
import selectors
import socket
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Protocol

import serial

from appmode.errors import AppmodeError
from appmode.files import temporary_beside
from appmode.line.uart import misread
from appmode.ports.target import parse_device
from appmode.ports.urls import BAUD, NO_PTY, explain_open_error
from appmode.protocol import params

Log = Callable[[str], None]


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

    details: tuple[str, ...] = ()

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
            self.details = (f"link: {link} -> {self.url}",)
        self._sel = sel
        sel.register(self._master, selectors.EVENT_READ, self)

    def pause(self, paused: bool) -> None:
        """Stop (or go on) reading: what is not read waits in the pty."""
        if paused:
            self._sel.unregister(self._master)
        else:
            self._sel.register(self._master, selectors.EVENT_READ, self)

    def read(self, size: int, ready: object) -> bytes:
        """At most `size` bytes from the client (the selector found `ready` readable)."""
        try:
            data = os.read(self._master, size)
        except (BlockingIOError, InterruptedError):
            return b""
        return self._misread(data, to_board=True)

    def write(self, data: bytes) -> None:
        if self.baud is not None:
            data = self._misread(data, to_board=False)
        self._out.write(data, self._write_master)

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
    descriptor under /proc, so a link left by a board that died leads nowhere — never to
    the pty number another program (or another board's other port) took since; elsewhere
    the device. The link's line names the device it reaches."""
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

    details: tuple[str, ...] = ()

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
        family = socket.AF_INET6 if ":" in host else socket.AF_INET  # [::1]: IPv6
        try:
            self._listener = socket.create_server((host, port), family=family)
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                raise AppmodeError(
                    f"TCP port {host}:{port} is already in use: pick another with --listen "
                    f"HOST:PORT (port 0 picks a free one), or stop the program using it"
                ) from None
            raise AppmodeError(f"cannot listen on {host}:{port}: {exc.strerror}") from None
        self._listener.setblocking(False)
        bound_host, bound_port = self._listener.getsockname()[:2]
        shown = f"[{bound_host}]" if family == socket.AF_INET6 else bound_host
        self.url = f"socket://{shown}:{bound_port}"
        self._client: socket.socket | None = None
        self._gone = False
        """A write found the client gone: write no more, read what it sent until the end."""
        self._out = Overrun(log, "the TCP client")
        self._paused = False
        sel.register(self._listener, selectors.EVENT_READ, self)

    def pause(self, paused: bool) -> None:
        """Stop (or go on) reading the client: what is not read waits in the socket."""
        self._paused = paused
        if self._client is not None:
            if paused:
                self._sel.unregister(self._client)
            else:
                self._sel.register(self._client, selectors.EVENT_READ, self)

    def read(self, size: int, ready: object) -> bytes:
        """A new client on the listener, or at most `size` bytes from the client."""
        if ready is self._listener:
            self._accept()
            return b""
        return self._receive(size)

    def _accept(self) -> None:
        try:
            conn, peer = self._listener.accept()
        except (BlockingIOError, InterruptedError):
            return
        if self._client is not None:
            self._log(f"refused a client from {peer[0]}:{peer[1]}: one client at a time")
            conn.close()
            return
        conn.setblocking(False)
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._client = conn
        self._gone = False
        if not self._paused:
            self._sel.register(conn, selectors.EVENT_READ, self)
        self._log(f"client connected from {peer[0]}:{peer[1]}")

    def _receive(self, size: int) -> bytes:
        if self._client is None:
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
        if self._client is None or self._gone:
            return
        client = self._client
        try:
            self._out.write(data, client.send)
        except OSError:
            # the client has gone; what it sent before is still to be read (its last
            # stop, often), so the connection ends when a read finds its end
            self._gone = True

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

    details: tuple[str, ...] = ()

    def __init__(
        self, sel: selectors.BaseSelector, log: Log, device: str, baud: int = BAUD
    ) -> None:
        path, given = parse_device(device)
        baud = given or baud
        try:
            self._port = serial.Serial(path, baudrate=baud, timeout=0, exclusive=True)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise AppmodeError(explain_open_error(path, exc)) from None
        self.url = path
        self.baud: int | None = baud
        self._sel = sel
        sel.register(self._port.fileno(), selectors.EVENT_READ, self)

    def pause(self, paused: bool) -> None:
        """Stop (or go on) reading: what is not read waits in the OS buffer."""
        if paused:
            self._sel.unregister(self._port.fileno())
        else:
            self._sel.register(self._port.fileno(), selectors.EVENT_READ, self)

    def read(self, size: int, ready: object) -> bytes:
        data: bytes = self._port.read(max(1, min(size, self._port.in_waiting)))
        return data

    def write(self, data: bytes) -> None:
        if data:
            self._port.write(data)

    def close(self) -> None:
        self._port.close()


class Endpoint(Protocol):
    """What the board server asks of an endpoint (the three above, and the Bluetooth
    stand-in's)."""

    url: str
    baud: int | None
    details: tuple[str, ...]
    """Lines `appmode board` prints after the URLs (none but the Bluetooth stand-in's)."""

    def pause(self, paused: bool) -> None: ...
    def read(self, size: int, ready: object) -> bytes: ...
    def write(self, data: bytes) -> None: ...
    def close(self) -> None: ...


def parse_listen(text: str, option: str = "--listen") -> tuple[str, int]:
    """`PORT` or `HOST:PORT` (host 127.0.0.1 by default). An IPv4 address in a short or
    numeric form the system also takes (`127.1`, `0x7f000001`, `0`) is written out as the
    address it binds, so that what is loopback or every address is seen as such."""
    host, _, port = text.rpartition(":")
    number = params.whole(port)
    if number is None or number > 65535:
        raise AppmodeError(f"{option} {text!r}: expected HOST:PORT or PORT, e.g. 127.0.0.1:5000")
    host = host.strip("[]") or "127.0.0.1"
    if host.isascii() and not host.isalpha():  # a name is kept as it is
        with contextlib.suppress(OSError):
            host = socket.inet_ntoa(socket.inet_aton(host))
    return host, number


MakeEndpoint = Callable[[selectors.BaseSelector, Log], Endpoint]
"""Opens an endpoint on the server's selector: an endpoint class with its options bound
(`partial(TcpEndpoint, host=…, port=…)`)."""
