"""Classic SPP links through the profile API (org.bluez.Profile1's NewConnection): the
stand-in hands each side of a link a socket of a socket pair, and carries the bytes
between a central's socket and a server's."""

from __future__ import annotations

import asyncio
import contextlib
import socket
from collections.abc import Callable
from dataclasses import dataclass, field

from dbus_fast import DBusError
from dbus_fast.aio import MessageBus

from appmode.bluetooth.calls import call
from appmode.bluetooth.loop import chunks
from appmode.bluetooth.standin.devices import Device

Log = Callable[[str], None]


async def new_connection(bus: MessageBus, profile: tuple[str, str], device: str) -> socket.socket:
    """Our end of a socket pair whose other end went to `profile`'s (bus name, object
    path) NewConnection for `device`; DBusError if the profile refused it."""
    mine, theirs = socket.socketpair()
    sender, path = profile
    try:
        await call(
            bus,
            sender,
            path,
            "org.bluez.Profile1",
            "NewConnection",
            "oha{sv}",
            [device, 0, {}],
            [theirs.fileno()],
        )
    except DBusError as exc:
        mine.close()
        why = exc.text or exc.type
        raise DBusError(
            "org.bluez.Error.Failed", f"the profile refused the connection: {why}"
        ) from None
    finally:
        theirs.close()
    mine.setblocking(False)
    return mine


class SppLinks:
    """The SPP links between centrals and servers on the bus, one per device; `changed`
    is called when one starts or ends."""

    def __init__(self, log: Log, changed: Callable[[], None]) -> None:
        self._log, self._changed = log, changed
        self._links: dict[str, _Link] = {}

    async def connect(
        self,
        bus: MessageBus,
        device: Device,
        client: tuple[str, str],
        server: tuple[str, str],
        central: str,
    ) -> None:
        """Link the central's profile `client` to the server's profile `server`."""
        if device.path in self._links:
            raise DBusError("org.bluez.Error.AlreadyConnected", "Already Connected")
        to_client = await new_connection(bus, client, device.path)
        try:
            to_server = await new_connection(bus, server, central)
        except BaseException:
            to_client.close()
            raise
        link = self._links[device.path] = _Link((to_client, to_server))
        device.set_state(True)
        self._log(f"spp: {device.label} connected")
        self._changed()
        for source, sink in ((to_client, to_server), (to_server, to_client)):
            link.carriers.append(asyncio.ensure_future(self._carry(source, sink, device)))

    async def _carry(self, source: socket.socket, sink: socket.socket, device: Device) -> None:
        loop = asyncio.get_running_loop()
        with contextlib.suppress(OSError):  # the other side's end: the link ends
            async for data in chunks(source):
                await loop.sock_sendall(sink, data)
        self.disconnect(device)

    def disconnect(self, device: Device) -> None:
        link = self._links.pop(device.path, None)
        if link is not None:
            link.close()
        if device.connected:
            device.set_state(False)
            self._log(f"spp: {device.label} disconnected")
            self._changed()

    def close(self) -> None:
        for link in self._links.values():
            link.close()
        self._links.clear()


@dataclass
class _Link:
    """An SPP link the stand-in carries: the client's and the server's sockets, and the
    two tasks that copy between them."""

    sockets: tuple[socket.socket, socket.socket]
    carriers: list[asyncio.Task[None]] = field(default_factory=list)

    def close(self) -> None:
        for task in self.carriers:
            if task is not asyncio.current_task():
                task.cancel()  # before the close: the loop must stop watching the socket
        loop = asyncio.get_running_loop()
        for sock in self.sockets:
            loop.remove_reader(sock)  # no closed descriptor stays watched
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
            sock.close()
