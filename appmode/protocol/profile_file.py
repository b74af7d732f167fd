"""Profiles as data files: what a firmware of the family sends and takes on its APP port,
for a host — its records' fields, its parameters and their scales, its pages — in TOML
(`appmode/protocol/profiles/*.toml` ship, as the package's data `profiles`; `--profile
PATH` is a user's own, read by `board.profiles.load`). No file is opened here.

What a simulated board *does* is code (`board/profiles.py`); this is what a host shows.
The tables appmode's codec reads (`params.PARAMS`, the A record layouts) come from the
shipped `sheet` and `minibalance` files: one source of truth.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from functools import cache

from appmode.protocol.chassis_profile import ChassisSpec, chassis_spec
from appmode.protocol.profile_checks import (
    SCALE_TEXT,
    in_scales,
    letters,
    number,
    plain,
    text_value,
    under,
    whole,
)

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from typing import Any, NamedTuple
else:
    from appmode.protocol.tuples import NamedTuple

SHIPPED = ("sheet", "minibalance", "balance", "wheeltec-mec", "wheeltec-akm", "wheeltec-diff")
"""The profiles appmode ships, in the order `profile list` shows them (the command line's
options.SHIPPED_PROFILES names them too: a test keeps the two equal)."""
MAX_SIZE = 256_000
"""The largest profile file read, in bytes."""
A_FIELDS = 4
"""Fields of an A record: `{A f0:f1:f2:f3}$` for every firmware of the family."""
MAX_FIELDS = 9
"""At most nine fields in a B record, nine parameters (`{n:v}`: n is one digit, 0–8)."""


class ProfileError(ValueError):
    """What is wrong with a profile file, one line a mistake."""

    def __init__(self, where: str, problems: list[str]) -> None:
        super().__init__("\n".join(f"{where}: {problem}" for problem in problems))
        self.problems = problems


class Field(NamedTuple):
    """One field of a record: its name (a JSON key), a label for people, its unit;
    field = scale × the quantity, sent signed or as a magnitude, wrapping at `wrap`
    if it does (an unsigned byte: 256); whether it grows with the car's speed, or is
    the battery's percentage."""

    name: str
    label: str
    unit: str
    scale: float = 1.0
    signed: bool = True
    wrap: int | None = None
    motion: bool = False
    battery: bool = False


class ParamSpec(NamedTuple):
    """One parameter of the `{n:v}` / `{C…}$` set: the frame's integer runs from
    minimum to maximum and is `scale` × the user's value (a gain sent ×100: scale 100)."""

    name: str
    label: str
    minimum: int
    maximum: int
    default: int
    scale: float = 1.0


class ProfileFile(NamedTuple):
    """A firmware's APP port as a host sees it."""

    name: str
    description: str
    source: str
    baud: int
    period_ms: tuple[int, int]
    """Shortest and longest time between records."""
    control_port: bool
    """It has the binary control port (UART2, `FF FE` frames)."""
    saves: bool
    """`{Q:W}` writes the parameters to flash."""
    replies: tuple[str, ...]
    """What it sends besides records (`##$` before a C record, in some builds)."""
    pages: Mapping[str, str]
    """Letters that switch the app's page, and the page's name."""
    speed_keys: Mapping[str, int]
    """Letters that change the speed by themselves, and by how much."""
    a: tuple[Field, ...]
    b: tuple[Field, ...]
    params: tuple[ParamSpec, ...]
    speed_param: str | None
    """The parameter the speed keys (+, −) change (`max_speed`), or None: none does
    (`speed_param = ""` in a file that is `like` one that has it)."""
    boot: str
    """Text its start-up output holds (the sensor's messages), or ""."""
    velocity_si: tuple[float, float]
    """What one velocity unit is: metres a second of x and y, radians a second of z
    (WHEELTEC's firmware counts mm/s and mrad/s: 0.001 each, the default)."""
    chassis: ChassisSpec | None
    """A WHEELTEC board's chassis port (`7B … 7D` frames), or None: it has none."""
    path: str
    """Where it was read from (a file's path, or a shipped profile's name)."""
    text: str
    """The file as it was read (`profile show --toml` prints it)."""


@cache
def shipped(name: str) -> ProfileFile:
    """A profile appmode ships, from the package's own data (`profiles`: each file's text
    and its TOML as read, made from `profiles/NAME.toml`)."""
    from appmode.protocol import profiles

    if name not in SHIPPED:
        raise ProfileError(name, [f"no shipped profile: choose one of {', '.join(SHIPPED)}"])
    return parse(profiles.TEXTS[name], f"{name} (shipped)", ours=True, data=profiles.DATA[name])


def _toml(text: str, where: str) -> dict[str, Any]:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProfileError(where, [f"not TOML: {exc}"]) from None
    except RecursionError:
        raise ProfileError(where, ["nested too deeply: a profile's values are flat"]) from None


def parse(
    text: str, where: str, ours: bool = False, data: dict[str, Any] | None = None
) -> ProfileFile:
    """A profile file's text checked and read (`ours`: one appmode ships, whose name
    is one of SHIPPED; a user's may not take those names; `data`: the text's TOML
    already read)."""
    if data is None:
        data = _toml(text, where)
    problems: list[str] = []
    base: ProfileFile | None = None
    like = data.get("like")
    if like is not None:
        if like not in SHIPPED or like == data.get("name"):
            problems.append(f"like = {like!r}: name a shipped profile ({', '.join(SHIPPED)})")
        else:
            base = shipped(like)
    profile = _build(data, base, where, problems.append)
    if profile is not None and profile.name in SHIPPED and not ours:
        problems.append(
            f"name = {profile.name!r}: a shipped profile's name (a recording would name that "
            "firmware): call yours something else"
        )
    if problems or profile is None:
        raise ProfileError(where, problems)
    return profile._replace(text=text)


TOP = {
    "name", "description", "source", "like", "baud", "period_ms", "control_port", "saves",
    "replies", "pages", "speed_keys", "records", "params", "defaults", "boot", "speed_param",
    "velocity_si", "chassis",
}  # fmt: skip
SI_DEFAULT = (0.001, 0.001)
"""A velocity unit, when a profile does not say: mm/s and mrad/s, as WHEELTEC counts."""
FIELD_KEYS = {"name", "label", "unit", "scale", "signed", "wrap", "motion", "battery"}
PARAM_KEYS = {"name", "label", "minimum", "maximum", "default", "scale"}


def _build(
    data: dict[str, Any], base: ProfileFile | None, where: str, problem: Callable[[str], None]
) -> ProfileFile | None:
    for key in sorted(set(data) - TOP):
        problem(f"unknown key {key!r}: the keys are {', '.join(sorted(TOP))}")
    name = text_value(data, "name", problem, pattern=True, dashes=True)
    description = text_value(data, "description", problem, base.description if base else None)
    source = text_value(data, "source", problem, base.source if base else None)
    baud = data.get("baud", base.baud if base else 9600)
    if not whole(baud) or baud <= 0:
        problem(f"baud = {baud!r}: a rate in bits a second, such as 9600")
    period = data.get("period_ms", list(base.period_ms) if base else None)
    if not (
        isinstance(period, list)
        and len(period) == 2
        and all(whole(p) for p in period)
        and 0 < period[0] <= period[1] <= 60_000
    ):
        problem(f"period_ms = {period!r}: [shortest, longest] in ms, such as [50, 50]")
        period = [0, 0]
    flags = {}
    for key in ("control_port", "saves"):
        flags[key] = data.get(key, getattr(base, key) if base else None)
        if flags[key] is None:
            problem(f"{key} is missing: {key} = true or false")
        elif not isinstance(flags[key], bool):
            problem(f"{key} = {flags[key]!r}: true or false")
    replies = data.get("replies", list(base.replies) if base else [])
    if not (isinstance(replies, list) and all(plain(r) and r for r in replies)):
        problem(f'replies = {replies!r}: a list of texts, such as ["##$"]')
        replies = []
    boot = data.get("boot", base.boot if base else "")
    if not plain(boot):
        problem(f'boot = {boot!r}: a text its start-up output holds, such as "mpu_set_sensor"')
        boot = ""
    pages = letters(data, "pages", str, problem, base.pages if base else None)
    speed_keys = letters(data, "speed_keys", int, problem, base.speed_keys if base else None)
    records = data.get("records", {})
    if not isinstance(records, dict) or set(records) - {"A", "B"}:
        problem("[records] holds A and B, each a list of fields")
        records = {}
    a = _fields(records, "A", problem, base.a if base else None)
    b = _fields(records, "B", problem, base.b if base else None)
    if a is not None and len(a) != A_FIELDS:
        problem(f"records.A has {len(a)} fields: an A record has {A_FIELDS}")
    elif a is not None and not any(field.motion for field in a):
        problem("records.A: no field says motion = true: mark those that show the motion")
    params = _params(data, problem, base.params if base else None)
    speed_param = data.get("speed_param", base.speed_param if base else None) or None  # "": none
    names = [p.name for p in params or ()]
    if speed_param is not None and params is not None and speed_param not in names:
        problem(f"speed_param = {speed_param!r}: name one of the parameters ({', '.join(names)})")
    velocity_si = _velocity_si(data, base, problem)
    chassis = chassis_spec(data, base.chassis if base else None, problem)
    if not isinstance(name, str) or a is None or b is None or params is None:
        return None
    return ProfileFile(
        name,
        str(description),
        str(source),
        int(baud) if whole(baud) else 0,
        (int(period[0]), int(period[1])),
        bool(flags["control_port"]),
        bool(flags["saves"]),
        tuple(replies),
        pages,
        speed_keys,
        a,
        b,
        params,
        speed_param,
        boot,
        velocity_si,
        chassis,
        where,
        "",
    )


def _velocity_si(
    data: dict[str, Any], base: ProfileFile | None, problem: Callable[[str], None]
) -> tuple[float, float]:
    """What one velocity unit is (m/s of x and y, rad/s of z): the file's, its base's,
    or SI_DEFAULT."""
    given = data.get("velocity_si", list(base.velocity_si) if base else list(SI_DEFAULT))
    if not (
        isinstance(given, list)
        and len(given) == 2
        and all(number(v) and 1e-9 <= v <= 1e3 for v in given)
    ):
        problem(
            f"velocity_si = {given!r}: [metres a second, radians a second] one velocity "
            "unit of x and y, and of z, is, such as [0.001, 0.001]"
        )
        return SI_DEFAULT
    return float(given[0]), float(given[1])


def _fields(
    records: Mapping[str, Any],
    kind: str,
    problem: Callable[[str], None],
    inherited: tuple[Field, ...] | None,
) -> tuple[Field, ...] | None:
    if kind not in records:
        if inherited is None:
            problem(f"records.{kind} is missing: {kind} = [ {{ name = …, unit = … }}, … ]")
        return inherited
    entries = records[kind]
    if not isinstance(entries, list) or not 1 <= len(entries) <= MAX_FIELDS:
        problem(f"records.{kind}: a list of 1–{MAX_FIELDS} fields")
        return None
    fields: list[Field] = []
    for i, entry in enumerate(entries):
        at = f"records.{kind}[{i}]"
        if not isinstance(entry, dict):
            problem(f'{at}: a field is a table, {{ name = "…", unit = "…" }}')
            continue
        for key in sorted(set(entry) - FIELD_KEYS):
            problem(f"{at}: unknown key {key!r}: a field has {', '.join(sorted(FIELD_KEYS))}")
        name = text_value(entry, "name", under(at, problem), pattern=True)
        scale = entry.get("scale", 1.0)
        if not in_scales(scale):
            problem(f"{at}: scale = {scale!r}: {SCALE_TEXT} (field = scale × value)")
        wrap = entry.get("wrap")
        if wrap is not None and (not whole(wrap) or not 2 <= wrap <= 2**32):
            problem(f"{at}: wrap = {wrap!r}: where the field wraps, such as 256")
        flags = {k: entry.get(k, k == "signed") for k in ("signed", "motion", "battery")}
        for key, value in flags.items():
            if not isinstance(value, bool):
                problem(f"{at}: {key} = {value!r}: true or false")
        unit, label = entry.get("unit", ""), entry.get("label", name)
        if not plain(unit) or not plain(label):
            problem(f"{at}: label and unit are texts of a line, no control characters")
        if name is not None:
            fields.append(
                Field(name, str(label), str(unit), float(scale) if in_scales(scale) else 1.0,
                      flags["signed"] is True, wrap if whole(wrap) else None,
                      flags["motion"] is True, flags["battery"] is True)
            )  # fmt: skip
    names = [f.name for f in fields]
    for twice in sorted({n for n in names if names.count(n) > 1}):
        problem(f"records.{kind}: two fields are called {twice!r}")
    if sum(f.battery for f in fields) > 1:
        problem(f"records.{kind}: one battery field at most")
    return tuple(fields) if len(fields) == len(entries) else None


def _params(
    data: Mapping[str, Any],
    problem: Callable[[str], None],
    inherited: tuple[ParamSpec, ...] | None,
) -> tuple[ParamSpec, ...] | None:
    entries = data.get("params")
    if entries is None:
        if inherited is None:
            problem("[[params]] is missing: one [[params]] table a parameter, in order")
            return None
        specs = list(inherited)
    elif not isinstance(entries, list) or not 1 <= len(entries) <= MAX_FIELDS:
        problem(f"[[params]]: 1–{MAX_FIELDS} tables, one a parameter, in order")
        return None
    else:
        specs = []
        for i, entry in enumerate(entries):
            spec = _param(entry, f"params[{i}]", problem)
            if spec is not None:
                specs.append(spec)
        if len(specs) != len(entries):
            return None
    defaults = data.get("defaults")
    if defaults is not None:
        if not (
            isinstance(defaults, list)
            and len(defaults) == len(specs)
            and all(
                whole(d) and s.minimum <= d <= s.maximum
                for d, s in zip(defaults, specs, strict=True)
            )
        ):
            problem(f"defaults: {len(specs)} whole numbers, each in its parameter's range")
            return None
        specs = [
            ParamSpec(s.name, s.label, s.minimum, s.maximum, d, s.scale)
            for s, d in zip(specs, defaults, strict=True)
        ]
    names = [s.name for s in specs]
    for twice in sorted({n for n in names if names.count(n) > 1}):
        problem(f"[[params]]: two parameters are called {twice!r}")
    return tuple(specs)


def _param(entry: object, at: str, problem: Callable[[str], None]) -> ParamSpec | None:
    if not isinstance(entry, dict):
        problem(f"{at}: a [[params]] table")
        return None
    for key in sorted(set(entry) - PARAM_KEYS):
        problem(f"{at}: unknown key {key!r}: a parameter has {', '.join(sorted(PARAM_KEYS))}")
    name = text_value(entry, "name", under(at, problem), pattern=True)
    low, high = entry.get("minimum", 0), entry.get("maximum")
    default, scale = entry.get("default", low), entry.get("scale", 1.0)
    if (
        not (isinstance(low, int) and isinstance(high, int))
        or isinstance(low, bool)
        or isinstance(high, bool)
        or not 0 <= low <= high <= 0xFFFF_FFFF
    ):
        problem(
            f"{at}: minimum = {low!r}, maximum = {high!r}: "
            "whole numbers, 0 ≤ minimum ≤ maximum < 2³²"
        )
        return None
    if not isinstance(default, int) or isinstance(default, bool) or not low <= default <= high:
        problem(f"{at}: default = {default!r}: a whole number in {low}–{high}")
        return None
    if not in_scales(scale):
        problem(f"{at}: scale = {scale!r}: {SCALE_TEXT} (the frame's integer = scale × value)")
        return None
    if name is None:
        return None
    label = entry.get("label", name)
    if not isinstance(label, str) or not plain(label):
        problem(f"{at}: label = {label!r}: a text of a line, no control characters")
        return None
    return ParamSpec(name, label, low, high, default, float(scale))
