"""The checks of a profile file's values, each saying what is wrong as a problem: whole
numbers, scales, texts a view can show as they are, tables of letters."""

from __future__ import annotations

from collections.abc import Callable, Mapping

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from typing import Any

NAME_CHARACTERS = frozenset("abcdefghijklmnopqrstuvwxyz0123456789_")
"""A profile's, a field's and a parameter's name: these, a letter first (a JSON key and
a command word)."""
SCALES = (1e-6, 1e6)
"""The smallest and largest scale a field or a parameter may have: beyond them a value
is no longer a number a frame or a record can carry (inf, 1e-320)."""
MAX_TEXT = 200
"""The longest text (a description, a label, a unit, a page's name), in characters."""


def under(at: str, problem: Callable[[str], None]) -> Callable[[str], None]:
    """Problems said of a part of the file (`records.A[2]: …`)."""

    def said(text: str) -> None:
        problem(f"{at}: {text}")

    return said


def whole(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


SCALE_TEXT = f"a number from {SCALES[0]:g} to {SCALES[1]:g}"


def in_scales(value: object) -> bool:
    return number(value) and SCALES[0] <= value <= SCALES[1]  # type: ignore[operator]


def plain(value: object) -> bool:
    """A text a view can show as it is: no control characters, not too long."""
    return isinstance(value, str) and len(value) <= MAX_TEXT and value.isprintable()


def text_value(
    data: Mapping[str, Any],
    key: str,
    problem: Callable[[str], None],
    inherited: str | None = None,
    pattern: bool = False,
    dashes: bool = False,
) -> str | None:
    value = data.get(key, inherited)
    if value is None:
        problem(f'{key} is missing: {key} = "…"')
        return None
    if not isinstance(value, str) or not value.strip():
        problem(f'{key} = {value!r}: a text, {key} = "…"')
        return None
    if not plain(value):
        problem(f"{key} = {value!r}: a line of at most {MAX_TEXT} characters, no control ones")
        return None
    allowed = NAME_CHARACTERS | {"-"} if dashes else NAME_CHARACTERS
    if pattern and not (value[0].isalpha() and value[-1] != "-" and set(value) <= allowed):
        kinds = "lower-case letters, digits, _" + (" and -" if dashes else "")
        problem(f"{key} = {value!r}: {kinds}, a letter first")
        return None
    return value


def letters(
    data: Mapping[str, Any],
    key: str,
    kind: type,
    problem: Callable[[str], None],
    inherited: Mapping[str, Any] | None,
) -> dict[str, Any]:
    table = data.get(key, dict(inherited) if inherited is not None else {})
    what = "a page's name" if kind is str else "a speed change"
    good = isinstance(table, dict) and all(
        isinstance(k, str)
        and len(k) == 1
        and "A" <= k <= "Z"
        and (plain(v) and bool(v.strip()) if kind is str else whole(v) and abs(v) <= 2**31)
        for k, v in table.items()
    )
    if not good:
        problem(f"[{key}]: a capital letter = {what}, one a line, such as K = …")
        return {}
    return dict(table)
