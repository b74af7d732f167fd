"""The phone's side of `appmode tap` over the air: appmode advertised as the car's module,
read and written as a port. What the phone writes is read here; what is written here is
notified to it. When the phone leaves, a read says so (`LinkLeft`): the tap ends."""

from __future__ import annotations

import contextlib
import threading

from appmode.bluetooth.advertise.admission import ANY_PHONE, Admission
from appmode.bluetooth.advertise.application import AdvertisedModule, Log
from appmode.bluetooth.inbox import Inbox
from appmode.bluetooth.loop import LoopThread
from appmode.bluetooth.uuids import UartService
from appmode.ports.urls import BAUD, LinkLeft

START = 10.0
"""Seconds BlueZ may take to register the module."""


class AdvertisedPort:
    """A module named `name` offering `service`, until closed."""

    baudrate = BAUD
    """The module's UART rate, which the tap paces the phone's bytes at."""

    def __init__(
        self,
        name: str,
        service: UartService,
        log: Log,
        timeout: float,
        admission: Admission = ANY_PHONE,
    ) -> None:
        self._timeout = timeout
        self._ready = threading.Condition()
        self._received = Inbox(self._ready)
        self._left: str | None = None
        self._runner = LoopThread("advertised module")
        self.module = AdvertisedModule(
            name, service, log, self._received.add, left=self._gone, admission=admission
        )
        try:
            self._runner.run(self.module.start(), START)
        except BaseException:
            self.close()
            raise

    def _gone(self, why: str) -> None:
        with self._ready:
            self._left = self._left or why  # the first reason heard
            self._ready.notify_all()

    @property
    def in_waiting(self) -> int:
        return len(self._received)

    def read(self, size: int = 1) -> bytes:
        """What the phone wrote (at most `size` bytes), waiting at most the timeout;
        once the phone has left and all it wrote was read, LinkLeft."""
        return self._received.read(size, self._timeout, self._check)

    def _check(self) -> None:
        if self._left is not None:
            raise LinkLeft(self._left)

    def write(self, data: bytes) -> int:
        """To the phone, as the module's notifications (or its SPP link)."""
        self._runner.loop.call_soon_threadsafe(self.module.send, bytes(data))
        return len(data)

    def close(self) -> None:
        """Unregister the module and stop its loop."""
        if not self._runner.loop.is_closed():
            with contextlib.suppress(TimeoutError):
                self._runner.run(self.module.stop(), 3.0)
            self._runner.close()
