"""A profile's parameters as a user reads and writes them: by name, in the user's units
(the balance car's `balance_kp 0.42` is the frame's `{0:42}`: scale 100), checked
against the profile's ranges. The sheet's own rules (system_mode's drive type) are
`params`'; these take any profile's table (`ParamSpec`s, from its file)."""

from __future__ import annotations

from collections.abc import Sequence

from appmode.errors import InvalidValue
from appmode.protocol import params
from appmode.protocol.profile_file import ParamSpec

Specs = tuple[ParamSpec, ...]
SHEET: Specs = params.SPECS
"""The sheet's nine, as its file declares them."""


def error(specs: Specs, index: int, value: int) -> str | None:
    """Why `value` (the frame's integer) cannot be parameter `index`, or None."""
    if specs == SHEET:
        return params.value_error(index, value)
    if not 0 <= index < len(specs):
        return f"no parameter {index}: indices are 0–{len(specs) - 1}"
    spec = specs[index]
    if not spec.minimum <= value <= spec.maximum:
        lo, hi = to_user(spec, spec.minimum), to_user(spec, spec.maximum)
        return f"{spec.name} (parameter {index}) must be in {lo}–{hi}, not {to_user(spec, value)}"
    return None


def check(specs: Specs, index: int, value: int) -> None:
    """InvalidValue naming the parameter and its range when `value` is not allowed."""
    why = error(specs, index, value)
    if why is not None:
        raise InvalidValue(why)


def lookup(specs: Specs, key: str) -> int:
    """A parameter's index, by name or number; InvalidValue lists the names."""
    number = params.whole(key)
    if number is not None and 0 <= number < len(specs):
        return number
    for index, spec in enumerate(specs):
        if spec.name == key:
            return index
    names = ", ".join(spec.name for spec in specs)
    raise InvalidValue(f"unknown parameter {key!r}: use 0–{len(specs) - 1} or one of {names}")


def from_user(spec: ParamSpec, text: str) -> int:
    """The frame's integer for what a user wrote (`0.42` with scale 100: 42); exact, or
    InvalidValue saying the step."""
    text = text.strip()
    if spec.scale == 1:
        number = params.whole(text)
        if number is None:
            raise InvalidValue(f"{spec.name} takes a whole number in {range_text(spec)}")
        return number
    from decimal import Decimal, DecimalException  # here: start-up (`decode` shows no value)

    try:
        if len(text) > 40 or not text.isascii() or text.startswith("+") or "_" in text:
            raise DecimalException
        frame = Decimal(text) * Decimal(repr(spec.scale))
        if not frame.is_finite() or not 0 <= frame <= spec.maximum:
            raise DecimalException
    except DecimalException:  # not a number, or out of every range (1e999999999)
        raise InvalidValue(f"{spec.name} takes a number in {range_text(spec)}") from None
    if frame != frame.to_integral_value():
        step = to_user(spec, 1)
        raise InvalidValue(f"{spec.name} takes steps of {step} in {range_text(spec)}")
    return int(frame)


def to_user(spec: ParamSpec, value: int) -> str:
    """The frame's integer as the user's value (42 with scale 100: `0.42`)."""
    if spec.scale == 1:
        return str(value)
    from decimal import Decimal  # here: start-up (`decode` of records with no scaled value)

    shown = Decimal(value) / Decimal(repr(spec.scale))
    text = format(shown.normalize(), "f")
    return text


def user_number(spec: ParamSpec, value: int) -> int | float:
    """The user's value as a JSON number."""
    return value if spec.scale == 1 else float(to_user(spec, value))


def range_text(spec: ParamSpec) -> str:
    return f"{to_user(spec, spec.minimum)}–{to_user(spec, spec.maximum)}"


def out_of_range(specs: Specs, values: Sequence[int]) -> tuple[str, ...]:
    """The names of the values outside their ranges (a board holds what it is sent)."""
    if specs == SHEET and params.values_error(values) is None:
        return ()  # the common case, at once: every C record a host decodes comes here
    return tuple(
        spec.name
        for index, (spec, value) in enumerate(zip(specs, values, strict=False))
        if error(specs, index, value) is not None
    )
