"""D-Bus method calls as the Bluetooth layer makes them: a call whose failure is a
`DBusError` (an error reply, or none), and a match rule added to the bus."""

from __future__ import annotations

from typing import Any

from dbus_fast import DBusError, Message, MessageType
from dbus_fast.aio import MessageBus

BLUEZ = "org.bluez"


async def call(
    bus: MessageBus,
    destination: str,
    path: str,
    interface: str,
    member: str,
    signature: str = "",
    body: list[Any] | None = None,
    unix_fds: list[int] | None = None,
) -> Message:
    """The reply to a method call; DBusError (the error's name and text) if it failed."""
    reply = await bus.call(
        Message(
            destination=destination,
            path=path,
            interface=interface,
            member=member,
            signature=signature,
            body=body or [],
            unix_fds=unix_fds or [],
        )
    )
    if reply is None:
        raise DBusError("org.freedesktop.DBus.Error.NoReply", f"{member}: no answer")
    if reply.message_type == MessageType.ERROR:
        why = reply.body[0] if reply.body and isinstance(reply.body[0], str) else ""
        raise DBusError(str(reply.error_name), why)
    return reply


async def add_match(bus: MessageBus, rule: str) -> None:
    """Have the bus route the signals `rule` matches to us."""
    await call(
        bus,
        "org.freedesktop.DBus",
        "/org/freedesktop/DBus",
        "org.freedesktop.DBus",
        "AddMatch",
        "s",
        [rule],
    )
