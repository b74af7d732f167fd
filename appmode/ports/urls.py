"""Open any board by URL or Target (docs/design.md, "Contracts"): a device path,
pyserial's URLs, `sim://`, `ble://` and `bt://`.

| URL | what |
|---|---|
| `/dev/ttyUSB0`, `COM3`, `/dev/rfcomm0`, `/dev/pts/4` | a serial port, 9600 8N1 unless `?baud=N` |
| `socket://HOST:PORT`, `rfc2217://HOST:PORT`, `loop://` | pyserial's own handlers |
| `sim://?drive=…&flash=…&pace=…` | the simulated board in-process |
| `ble://ADDRESS`, `bt://ADDRESS` | a Bluetooth module directly (bluetooth/) |

Every failure to open becomes one AppmodeError that says what to do.
"""

from __future__ import annotations

import errno
import importlib
import os
from typing import TYPE_CHECKING

import serial

from appmode import register_urls
from appmode.errors import AppmodeError
from appmode.ports.holders import holders
from appmode.ports.schemes import SCHEMES
from appmode.ports.target import AnyTarget, Target, as_target, parse_target

if TYPE_CHECKING:
    from appmode.ports.newpty import PtyPort

NO_PTY = "this system has no pseudo-terminals (Windows)"


BAUD = 9600
OWN_PORTS = {name: scheme.port for name, scheme in SCHEMES.items() if scheme.port is not None}
"""appmode's own port classes (pyserial's handlers for these schemes): they take the
Target itself, and say themselves what went wrong and what to do."""
register_urls()  # in the `appmode` program, here: it imports pyserial only to open a port


class LinkLeft(ConnectionError):
    """The other end of a link left it (a phone that disconnected from the module
    appmode serves): the end of a session, not a fault."""


def open_link(url: AnyTarget, timeout: float | None = 0.05, baud: int = BAUD) -> serial.SerialBase:
    """An open pyserial port for `url`, at `baud` (9600) 8N1 unless the URL says otherwise."""
    target = as_target(url)
    try:
        if target.scheme in OWN_PORTS:
            return _own_port(target, baud, timeout)
        if target.scheme:
            return serial.serial_for_url(target.url, baudrate=baud, timeout=timeout)
        _refuse_a_terminal(target.path)
        return serial.Serial(
            target.path, baudrate=target.baud or baud, timeout=timeout, exclusive=os.name == "posix"
        )
    except (serial.SerialException, ValueError, OSError) as exc:
        where = target.url if target.scheme else target.path
        raise AppmodeError(explain_open_error(where, exc, target.scheme)) from None


def _refuse_a_terminal(path: str) -> None:
    """AppmodeError when `path` is a pseudo-terminal some program has as its terminal (a
    shell's): frames written there would reach that program, not a board. Told on Linux;
    elsewhere nothing is refused."""
    device = os.path.realpath(path)
    if not device.startswith("/dev/pts/"):
        return
    from appmode.ports.holders import terminal_of
    from appmode.text import escaped

    users = terminal_of(device)
    if users:
        raise AppmodeError(
            f"{path} is not a board: it is the terminal of {escaped(str(users[0]))} (a board's "
            "pseudo-terminal is no program's terminal); use the path appmode board printed, "
            "or its --link name"
        )


def _own_port(target: Target, baud: int, timeout: float | None) -> serial.SerialBase:
    """One of appmode's own ports, given the Target (nothing parses its URL again)."""
    port: serial.SerialBase = importlib.import_module(OWN_PORTS[target.scheme]).Serial(
        None, baudrate=baud, timeout=timeout
    )
    port.target = target
    port.port = target.url
    port.open()
    return port


def port_target(port: serial.SerialBase) -> Target:
    """The Target an own port opens: the one `open_link` gave it, else its name parsed (a
    program that opens `serial.serial_for_url("sim://…")`); SerialException if bad."""
    given = getattr(port, "target", None)
    if isinstance(given, Target):
        return given
    try:
        return parse_target(port.portstr)
    except AppmodeError as exc:
        raise serial.SerialException(str(exc)) from None


LIST_PORTS = "list ports with: appmode ports"
RFCOMM_BIND = (
    "pair the car's Bluetooth module once (bluetoothctl: scan on, pair MAC, trust MAC; "
    "the PIN is often 1234), then bind it: sudo rfcomm bind 0 MAC 1"
)
LOST_ERRNOS = {
    getattr(errno, name)
    for name in ("EHOSTDOWN", "ECONNREFUSED", "ETIMEDOUT", "EHOSTUNREACH", "ECONNRESET")
    if hasattr(errno, name)
}
"""What opening a bound rfcomm port fails with when the module does not answer."""


def is_rfcomm(where: str) -> bool:
    return "rfcomm" in where.lower()


def explain_open_error(where: str, exc: Exception, scheme: str = "") -> str:
    code = getattr(exc, "errno", None)
    text = str(exc)
    if scheme in OWN_PORTS and scheme != "socket":  # its own message: what, then the fix
        return text
    if code == errno.ENOENT or "No such file" in text:
        if is_rfcomm(where):
            return f"no such port {where}: the Bluetooth serial port is not bound: {RFCOMM_BIND}"
        if os.path.islink(where):  # a board's --link, its board gone
            gone = os.readlink(where)
            board = gone.startswith(("/dev/pts/", "/proc/"))  # a board's pty, or its fd
            why = (
                "the pseudo-terminal of a board that has stopped (start it again with --link)"
                if board
                else "a device that is not there"
            )
            return f"no such port {where}: it is a link to {gone}, {why}; {LIST_PORTS}"
        return (
            f"no such port {where}: check the adapter is plugged in (and paired, for "
            f"Bluetooth); {LIST_PORTS}"
        )
    if is_rfcomm(where) and code in LOST_ERRNOS:
        return (
            f"the car's Bluetooth module did not answer on {where} "
            f"({getattr(exc, 'strerror', None) or text}): switch the car on and bring it "
            f"in range; a phone still connected to it keeps it: disconnect the phone"
        )
    if code == errno.EACCES or "Permission denied" in text:
        group = _group_of(where)
        return (
            f"permission denied opening {where}: add yourself to the {group} group "
            f"(sudo usermod -aG {group} $USER) and log in again"
        )
    if code == errno.EBUSY or "exclusively lock" in text or "busy" in text.lower():
        held = holders(where)
        who = f"held by {', '.join(map(str, held))}" if held else "another program has it open"
        return f"{where} is busy: {who}; close that program and retry"
    if "Connection refused" in text:
        return (
            f"nothing is listening at {where}: start the board (appmode board --listen "
            f"HOST:PORT) or check the address"
        )
    if "Name or service not known" in text or "nodename nor servname" in text:
        return f"unknown host in {where}: check the address"
    if code == errno.ENXIO or "No such device or address" in text:
        return f"{where} is not a device this program can open (no such device or address)"
    if code in (errno.ENOTTY, errno.EISDIR) or "Inappropriate ioctl" in text:
        what = "a folder" if code == errno.EISDIR else "not a terminal device"
        return f"{where} is not a serial port ({what}): name the car's port; {LIST_PORTS}"
    reason = getattr(exc, "strerror", None) or text  # pyserial repeats errno and path
    return f"cannot open {where} ({reason}): check the name; {LIST_PORTS}"


def _group_of(path: str) -> str:
    """The group that may open a device (dialout on most Linux systems, uucp on some)."""
    try:
        import grp  # POSIX only

        name = grp.getgrgid(os.stat(path).st_gid).gr_name
    except (ImportError, OSError, KeyError):
        return "dialout"
    return "dialout" if name == "root" else name


def new_pty() -> PtyPort:
    """A new pseudo-terminal for another program to open as its serial port (POSIX)."""
    try:
        from appmode.ports.newpty import PtyPort
    except ImportError:
        raise AppmodeError(
            f"{NO_PTY}: name a port (COM3, socket://HOST:PORT) instead of pty"
        ) from None
    return PtyPort()
