"""An asyncio event loop in a thread of its own, for the Bluetooth links: bleak and
dbus-fast are asynchronous, a pyserial port is not; and a socket read as it comes."""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import socket
import threading
from collections.abc import AsyncIterator, Coroutine
from typing import TypeVar

T = TypeVar("T")
READ = 4096
"""Bytes a socket read takes at most."""


async def chunks(link: socket.socket) -> AsyncIterator[bytes]:
    """What a socket brings, as it comes, until its end (or its error)."""
    loop = asyncio.get_running_loop()
    while True:
        try:
            data = await loop.sock_recv(link, READ)
        except OSError:
            return
        if not data:
            return
        yield data


class LoopThread:
    """Runs coroutines on its loop for callers in other threads."""

    def __init__(self, name: str) -> None:
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self.loop.run_forever, name=name, daemon=True)
        self._thread.start()

    def run(self, work: Coroutine[object, object, T], timeout: float | None) -> T:
        """`work`'s result; TimeoutError (the work cancelled) after `timeout` seconds."""
        future = asyncio.run_coroutine_threadsafe(work, self.loop)
        try:
            return future.result(timeout)
        except concurrent.futures.TimeoutError:
            future.cancel()
            raise TimeoutError from None

    def submit(self, work: Coroutine[object, object, T]) -> concurrent.futures.Future[T]:
        return asyncio.run_coroutine_threadsafe(work, self.loop)

    def close(self) -> None:
        """Cancel what still runs, stop the loop and its thread."""
        if self.loop.is_closed():
            return

        async def cancel_all() -> None:
            tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)

        if self._thread.is_alive():
            with contextlib.suppress(TimeoutError):
                self.run(cancel_all(), 2.0)
            self.loop.call_soon_threadsafe(self.loop.stop)
            self._thread.join(2.0)
        if not self._thread.is_alive():
            self.loop.close()
