"""`bt://AA:BB:CC:DD:EE:FF`: a paired classic module (HC-05, HC-06, JDY-31) over the
Serial Port profile, as a pyserial port — with no root and no `rfcomm` tool.

- Linux: BlueZ's profile API on the system bus: register the Serial Port profile
  (org.bluez.ProfileManager1), connect it (Device1.ConnectProfile), and take the socket
  BlueZ hands over (Profile1.NewConnection). It works on every Python build, with or
  without socket.AF_BLUETOOTH.
- Windows: a direct RFCOMM socket (channel 1 unless `?channel=N`).
- macOS: the system makes a paired module a serial port, /dev/cu.NAME: open that.

Writes are paced at the module's 9600 bps, as `ble://`'s are.
"""

from __future__ import annotations

import contextlib
import select
import socket
import sys
import time
from collections.abc import Callable, Coroutine

from serial import SerialBase, SerialException

from appmode.bluetooth.availability import NO_BLEAK, explain
from appmode.bluetooth.links.serial_port_profile import PAIR
from appmode.bluetooth.loop import LoopThread
from appmode.line.pacing import Ahead
from appmode.ports.radio import BT_USAGE, BtTarget
from appmode.ports.urls import port_target
from appmode.ports.waiting import bytes_waiting

CONNECT = 10.0
BAUD = 9600
AHEAD = 64
"""Bytes handed to the socket beyond what the module's UART has sent (a stop waits
behind no more than these)."""


class SppSerial(SerialBase):  # type: ignore[misc]  # pyserial has no types
    """A classic SPP module, opened by `bt://` URL."""

    def open(self) -> None:
        if self._port is None:
            raise SerialException("port must be configured before use")
        target = port_target(self).radio
        if not isinstance(target, BtTarget):
            raise SerialException(f"expected {BT_USAGE}, not {self.portstr!r}")
        self._target = target
        self._ahead = Ahead(BAUD, AHEAD)
        self._session: BluezSpp | None = None
        if sys.platform.startswith("linux"):
            try:
                self._session = BluezSpp(target)
            except ImportError:
                raise SerialException(NO_BLEAK) from None
            self._socket = self._session.socket
        elif hasattr(socket, "AF_BLUETOOTH") and hasattr(socket, "BTPROTO_RFCOMM"):
            self._socket = _rfcomm(target)
        elif sys.platform == "darwin":
            raise SerialException(
                f"on macOS a paired module is a serial port: open /dev/cu.NAME, not "
                f"{self.portstr} (appmode scan names it)"
            )
        else:
            raise SerialException(
                f"this Python has no Bluetooth sockets for {self.portstr}: use the "
                "module's serial port"
            )
        self._socket.setblocking(False)
        self.is_open = True

    def _reconfigure_port(self) -> None:
        """A radio link has no line settings to change."""

    def _lost(self, why: str) -> SerialException:
        return SerialException(f"the Bluetooth connection to {self._target.address} {why}")

    @property
    def in_waiting(self) -> int:
        if not self.is_open:
            raise SerialException("the port is not open")
        return bytes_waiting(self._socket)

    def read(self, size: int = 1) -> bytes:
        if not self.is_open:
            raise SerialException("the port is not open")
        ready, _, _ = select.select([self._socket], [], [], self._timeout)
        if not ready:
            return b""
        try:
            data = self._socket.recv(size)
        except BlockingIOError:
            return b""
        except OSError as exc:
            raise self._lost(f"was lost ({exc.strerror or exc})") from None
        if not data:
            raise self._lost("was lost")
        return data

    def write(self, data: bytes) -> int:
        if not self.is_open:
            raise SerialException("the port is not open")
        data = bytes(data)
        wait = self._ahead.delay(time.monotonic())
        if wait:
            time.sleep(wait)
        try:
            self._socket.setblocking(True)
            self._socket.sendall(data)
        except OSError as exc:
            raise self._lost(f"was lost ({exc.strerror or exc})") from None
        finally:
            with contextlib.suppress(OSError):
                self._socket.setblocking(False)
        self._ahead.wrote(len(data), time.monotonic())
        return len(data)

    def close(self) -> None:
        """What was written goes first (the socket's own close sends it), then the
        profile is let go."""
        if not self.is_open:
            return
        self.is_open = False
        wait = self._ahead.delay(time.monotonic()) + AHEAD * 10 / BAUD
        time.sleep(min(wait, 1.0))  # the last bytes reach the module before it hangs up
        with contextlib.suppress(OSError):
            self._socket.close()
        if self._session is not None:
            self._session.close()


def _rfcomm(target: BtTarget) -> socket.socket:
    """A direct RFCOMM socket (Windows; Linux Pythons built with Bluetooth have one too)."""
    link = socket.socket(socket.AF_BLUETOOTH, socket.SOCK_STREAM, socket.BTPROTO_RFCOMM)
    link.settimeout(CONNECT)
    try:
        link.connect((target.address, target.channel))
    except OSError as exc:
        link.close()
        raise SerialException(
            f"cannot connect to {target.address} ({exc.strerror or exc}): switch the car "
            f"on, bring it in range, and {PAIR.format(target.address)}"
        ) from None
    return link


class BluezSpp:
    """The Serial Port profile registered with BlueZ and connected to one device: `socket`
    is the connection BlueZ handed over."""

    def __init__(self, target: BtTarget) -> None:
        from appmode.bluetooth.links.serial_port_profile import (
            connect_spp,  # dbus-fast: ImportError if absent
        )

        self._runner = LoopThread(f"bt {target.address}")
        self._ending: Callable[[], Coroutine[object, object, None]] | None = None
        try:
            fd, self._ending = self._runner.run(connect_spp(target, CONNECT), CONNECT + 5)
        except TimeoutError:
            self._runner.close()
            raise SerialException(
                f"{target.address} did not answer within {CONNECT:g} s: switch the car on "
                "and bring it in range; a phone still connected to it keeps it: "
                "disconnect the phone"
            ) from None
        except SerialException:
            self._runner.close()
            raise
        except Exception as exc:
            self._runner.close()
            raise SerialException(explain(exc) or f"{target.address}: {exc}") from None
        self.socket = socket.socket(fileno=fd)

    def close(self) -> None:
        if self._ending is not None:
            with contextlib.suppress(Exception):
                self._runner.run(self._ending(), 3.0)
        self._runner.close()
