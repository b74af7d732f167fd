"""D-Bus signatures of BlueZ's API that dbus_fast.annotations does not name."""

from typing import Annotated

from dbus_fast.annotations import DBusSignature

DBusStrings = Annotated[list[str], DBusSignature("as")]
Nothing = Annotated[None, DBusSignature("")]
"""A method that returns nothing (what `-> None` says to mypy, and "" to D-Bus)."""
