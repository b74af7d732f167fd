"""`typing.NamedTuple` without importing `typing`, for the modules on the command line's
start-up path (`typing` alone was a tenth of `appmode decode`'s start-up). mypy reads
`typing.NamedTuple` in its place (`if TYPE_CHECKING:`); at run time a class written
`class Row(NamedTuple):` is `collections.namedtuple` of its annotated fields, their
defaults, and the rest of its body (methods, docstrings), as typing makes it."""

from __future__ import annotations

from collections import namedtuple

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


class _Maker(type):
    """Makes the namedtuple a `class X(NamedTuple):` statement describes."""

    def __new__(
        cls, name: str, bases: tuple[type, ...], body: dict[str, Any]
    ) -> Any:  # the namedtuple, not an instance of _Maker
        if bases == ():  # NamedTuple itself
            return super().__new__(cls, name, bases, body)
        fields = tuple(body.get("__annotations__", {}))
        defaults = [body[field] for field in fields if field in body]
        if any(field not in body for field in fields[len(fields) - len(defaults) :]):
            raise TypeError(f"{name}: a field without a default follows one with a default")
        made = namedtuple(name, fields, defaults=defaults, module=body.get("__module__"))  # type: ignore[misc]
        for key, value in body.items():
            if key not in fields and key not in ("__annotations__", "__module__", "__qualname__"):
                setattr(made, key, value)
        made.__annotations__ = body.get("__annotations__", {})
        return made


class NamedTuple(metaclass=_Maker):
    """Base a class on it as on `typing.NamedTuple`."""
