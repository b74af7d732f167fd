"""The names appmode advertises as the car's module (`board --advertise`, `tap
advertise:`): what fits an advertising packet. What a `ble://` or `bt://` URL names is
read once with the board's URL (ports/radio.py)."""

from __future__ import annotations

NAME_BYTES = 20
"""The longest name appmode advertises: with the flags and the UART service's 16-bit
UUID it still fits the 31 bytes of an advertising packet (a module's own name is 12)."""


def name_problem(name: str) -> str | None:
    """Why `name` cannot be advertised as a module's name, or None."""
    size = len(name.encode("utf-8"))
    if not name or not name.isprintable():
        return f"{name!r} is not a name to advertise: use printable characters, e.g. HC-08"
    if size > NAME_BYTES:
        return f"{name!r} is {size} bytes; an advertised name fits {NAME_BYTES} at most"
    return None
