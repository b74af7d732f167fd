"""Regular expressions compiled when first used: a module on the command line's start-up
path names its patterns at import without paying for them (a dozen compiled at import
were a twentieth of `appmode decode`'s start-up; most commands use none of them)."""

from __future__ import annotations

import re

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from typing import AnyStr


class _Deferred:
    """Stands for `re.compile(pattern)`: the first use compiles it, and each attribute
    asked for is then the compiled pattern's own, kept (as fast to call)."""

    def __init__(self, pattern: str | bytes) -> None:
        self._pattern = pattern

    def __getattr__(self, name: str) -> object:
        compiled = self.__dict__.get("_compiled") or re.compile(self._pattern)
        self.__dict__["_compiled"] = compiled
        value = getattr(compiled, name)
        self.__dict__[name] = value
        return value


def deferred(pattern: AnyStr) -> re.Pattern[AnyStr]:
    """`re.compile(pattern)`, compiled when first used."""
    return _Deferred(pattern)  # type: ignore[return-value]  # a Pattern in all it is asked
