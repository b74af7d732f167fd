"""The base of the protocol layer's small value classes: the events and the table rows.

They are written out rather than made with `dataclasses`: importing `dataclasses` (which
imports `inspect`) and generating a score of classes took about 10 ms, more than a third
of what pyserial's miniterm takes to start, and `appmode decode` needs them all
(bench/startup.py). A subclass names its fields in `_fields`, in its constructor's
order (`__slots__ = _fields = (...)`), and in `_shown` the ones that are compared and
shown (`raw` is neither); it writes its own `__init__`.
"""

from __future__ import annotations


class Slotted:
    """Equal when of the same class with equal shown fields; shown by them; not hashable
    (treat it as immutable all the same); pickled and copied by its constructor."""

    __slots__ = ()
    _fields: tuple[str, ...] = ()
    _shown: tuple[str, ...] = ()
    __match_args__: tuple[str, ...] = ()

    def __init_subclass__(cls) -> None:
        cls.__match_args__ = cls._fields  # type: ignore[misc]  # for `case Velocity(x, y)`

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return all(getattr(self, name) == getattr(other, name) for name in self._shown)

    def __repr__(self) -> str:
        shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in self._shown)
        return f"{type(self).__name__}({shown})"

    def __reduce__(self) -> tuple[type, tuple[object, ...]]:
        return type(self), tuple(getattr(self, name) for name in self._fields)


class Frozen(Slotted):
    """A `Slotted` whose fields cannot be set once built, and so is hashable."""

    __slots__ = ()

    def _fill(self, *values: object) -> None:
        """Set the fields, in `_fields` order: for `__init__` only."""
        for name, value in zip(self._fields, values, strict=True):
            object.__setattr__(self, name, value)

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable: cannot set {name!r}")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable: cannot delete {name!r}")

    def __hash__(self) -> int:
        return hash(tuple(getattr(self, name) for name in self._shown))
