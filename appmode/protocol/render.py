"""Views of decoded events: JSON objects for machines, one-line text for people."""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable, Iterator

from appmode.protocol import app as p
from appmode.protocol import layouts, param_values
from appmode.protocol.directions import PAGE_LETTERS, PAGE_NAMES
from appmode.protocol.escaping import escape, text_part
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.params import DEFAULTS
from appmode.text import counted

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from typing import Any


def record_names(letter: str, layout: Layout = VELOCITY) -> tuple[str, ...]:
    """The names of a record's fields, in order, as `layout` reads them."""
    if letter == "A":
        return layout.fields
    if letter == "B":
        return layout.b_names
    if letter == "C":
        return layout.param_names
    return ()


OTHER_KEYS = (
    "letter",
    "values",
    "direction",
    "numeric",
    "page",
    "mode",
    "index",
    "name",
    "value",
    "warning",
    "reason",
    "out_of_range",
    "terminated",
    "raw",
)


def json_keys(layout: Layout = VELOCITY) -> tuple[str, ...]:
    """Every key `to_json` may write with `layout`, in the order a table (CSV) shows them:
    its records' fields, then the other shipped A layouts' (a table of any transcript)."""
    names = [record_names(letter, layout) for letter in "ABC"]
    names += [a.fields for a in layouts.A_LAYOUTS.values()]
    return ("kind", *dict.fromkeys(name for group in names for name in group), *OTHER_KEYS)


KINDS = {"A": "velocity", "B": "attitude", "C": "params"}
"""The JSON `kind` of each record the family sends, whatever a profile's fields mean."""


def to_json(event: p.Event, layout: Layout = VELOCITY) -> dict[str, Any]:
    """One JSON-ready object: `kind`, the integer values (an A record's named as `layout`
    reads them), and `raw` (escaped bytes)."""
    body: dict[str, Any]
    if isinstance(event, p.RECORDS) and (
        not isinstance(event, p.OtherRecord)
        or len(event.values) == len(record_names(event.letter, layout))
    ):  # an other record named: a B record of a profile whose B has other than four fields
        names = record_names(event.letter, layout)
        body = {"kind": KINDS[event.letter], **dict(zip(names, event.values, strict=True))}
        odd = out_of_range(event.values, layout) if isinstance(event, p.ParamsRecord) else ()
        if odd:
            body["out_of_range"] = list(odd)
    elif isinstance(event, p.OtherRecord):
        body = {"kind": "record", "letter": event.letter, "values": list(event.values)}
    elif isinstance(event, p.Move):
        body = {
            "kind": "move",
            "direction": event.direction,
            "letter": event.letter,
            "numeric": event.numeric,
        }
    elif isinstance(event, p.Stop):
        body = {"kind": "stop"}
    elif isinstance(event, p.SwitchPage):
        body = {
            "kind": "page",
            "letter": event.letter,
            "page": PAGE_LETTERS[event.letter].value,
            "mode": PAGE_NAMES[event.letter],
        }
    elif isinstance(event, (p.ReadParams, p.SaveParams)):
        kind = "read_params" if isinstance(event, p.ReadParams) else "save_params"
        body = {"kind": kind}
        if event.warning is not None:
            body["warning"] = event.warning
    elif isinstance(event, p.SetParam):
        body = {"kind": "set_param", "index": event.index, "name": event.name, "value": event.value}
    elif isinstance(event, p.Noise):
        body = {"kind": "noise"}
    elif isinstance(event, p.Garbage):
        body = {"kind": "reply" if event.raw in layout.replies else "garbage"}
    else:
        body = {
            "kind": "bad_frame" if isinstance(event, p.BadFrame) else "malformed",
            "reason": event.reason,
        }
    if isinstance(event, (p.Velocity, p.Attitude, p.ParamsRecord, p.OtherRecord)) and (
        not event.terminated
    ):
        body["terminated"] = False
    body["raw"] = escape(event.raw)
    return body


@functools.cache
def _json() -> Callable[[object], str]:
    """json.dumps(…, ensure_ascii=False), json imported when first needed (start-up)."""
    import json

    return json.JSONEncoder(ensure_ascii=False).encode


def json_line(event: p.Event, layout: Layout = VELOCITY) -> str:
    """`to_json(event, layout)` as `json.dumps(…, ensure_ascii=False)` writes it. Whole A
    and B records whose text needs no JSON escaping are formatted directly: `appmode
    decode` spends its time here."""
    fast = layout is VELOCITY or (layout.sheet_b and isinstance(event, p.Attitude))
    if fast and isinstance(event, (p.Velocity, p.Attitude)) and event.terminated:
        raw = escape(event.raw)
        if '"' not in raw and "\\" not in raw:
            if isinstance(event, p.Velocity):
                return (
                    f'{{"kind": "velocity", "x": {event.x}, "y": {event.y}, "z": {event.z}, '
                    f'"extra": {event.extra}, "raw": "{raw}"}}'
                )
            return (
                f'{{"kind": "attitude", "pitch": {event.pitch}, "roll": {event.roll}, '
                f'"yaw": {event.yaw}, "battery": {event.battery}, "raw": "{raw}"}}'
            )
    return _json()(to_json(event, layout))


def motion_text(record: p.Velocity, layout: Layout = VELOCITY) -> str:
    """An A record's fields by name, as `layout` reads them: `x=0 y=500 z=0`."""
    values = (record.x, record.y, record.z, record.extra)
    shown = [f"{layout.fields[i]}={values[i]}" for i in layout.motion]
    if layout.battery is not None:
        shown.append(f"battery={values[layout.battery]}%")
    shown += [f"{layout.fields[i]}={values[i]}" for i in layout.extra_a]
    return " ".join(shown)


SHOWN_PARAMS = 1
"""Parameters a C record's description names (the record shows all nine; `params`
prints them as a table, `--json` by name)."""


def out_of_range(values: tuple[int, ...], layout: Layout = VELOCITY) -> tuple[str, ...]:
    """The names of a C record's values outside `layout`'s ranges (a board holds what it
    is sent: they are shown, flagged)."""
    if len(values) != len(layout.params):
        return ()
    return param_values.out_of_range(layout.params, values)


def describe(event: p.Event, layout: Layout = VELOCITY) -> str:
    """A short human description of an event (an A record's fields as `layout` reads them)."""
    if isinstance(event, p.Velocity):
        return f"velocity {motion_text(event, layout)}"
    if isinstance(event, p.Attitude) and layout.sheet_b:
        return (
            f"attitude pitch={event.pitch} roll={event.roll} yaw={event.yaw} "
            f"battery={event.battery}%"
        )
    if isinstance(event, (p.Attitude, p.OtherRecord)) and (
        event.letter == "B" and len(event.values) == len(layout.b_fields)
    ):
        values = event.values
        pairs = zip(layout.b_fields, values, strict=True)
        shown = (f"{f.name}={v}{'%' if f.battery else ''}" for f, v in pairs)
        return "attitude " + " ".join(shown)
    if isinstance(event, p.ParamsRecord):
        first = list(zip(layout.param_names, event.values, strict=False))[:SHOWN_PARAMS]
        text = "params " + " ".join(f"{k}={v}" for k, v in first) + " …"
        odd = out_of_range(event.values, layout)
        return text if not odd else f"{text} (out of range: {', '.join(odd)})"
    if isinstance(event, p.OtherRecord):
        return f"record {event.letter} {list(event.values)}"
    if isinstance(event, p.Move):
        return f"move {event.letter} (direction {event.direction})"
    if isinstance(event, p.Stop):
        return "stop"
    if isinstance(event, p.SwitchPage):
        return f"{PAGE_NAMES[event.letter]} mode, {PAGE_LETTERS[event.letter].value} page"
    if isinstance(event, (p.ReadParams, p.SaveParams)):
        text = "read parameters" if isinstance(event, p.ReadParams) else "save parameters"
        return text if event.warning is None else f"{text} ({event.warning})"
    if isinstance(event, p.SetParam):
        return f"set {event.name} = {event.value}"
    if isinstance(event, (p.BadFrame, p.Malformed)):
        return f"error: {event.reason}"
    if isinstance(event, p.Garbage) and event.raw in layout.replies:
        return f"reply (this firmware sends it besides records: {layout.name})"
    if event.raw.endswith(b"}$") and b"{" not in event.raw:
        return f"a record's end, its start missed ({counted(len(event.raw), 'byte')})"
    if event.raw and text_part(event.raw) == event.raw:
        return f"text, no record ({counted(len(event.raw), 'byte')})"
    return f"{counted(len(event.raw), 'undecodable byte')}"


MAX_RUN = 4096
"""Bytes one merged Noise or Garbage event holds at most: a longer run (a megabyte of
zeros) is several events, so memory stays bounded on any input."""


def coalesce(events: Iterable[p.Event]) -> Iterator[p.Event]:
    """Merge adjacent Noise or Garbage events into one event per run of bytes, of at
    most MAX_RUN bytes (in time linear in the run: the pieces are joined once)."""
    run: list[p.Noise | p.Garbage] = []
    size = 0
    for event in events:
        if run and type(event) is type(run[0]) and size + len(event.raw) <= MAX_RUN:
            run.append(event)
            size += len(event.raw)
            continue
        if run:
            yield _joined(run)
            run = []
        if isinstance(event, (p.Noise, p.Garbage)):
            run.append(event)
            size = len(event.raw)
        else:
            yield event
    if run:
        yield _joined(run)


def _joined(run: list[p.Noise | p.Garbage]) -> p.Noise | p.Garbage:
    return run[0] if len(run) == 1 else type(run[0])(b"".join(e.raw for e in run))


RAW_WIDTH = 34
"""Columns the bytes of a line are aligned to."""
LINE_WIDTH = 80
"""Columns a line fits in: the bytes' column narrows (and long bytes are cut with `…`)
to leave the description room."""
RAW_MIN = 16
"""Columns of bytes always shown."""


def line(time: float, direction: str, raw: bytes, text: str, shown: str | None = None) -> str:
    """`  1.234 < {A0:0:0:0}$   velocity …`: one event of a session, for people (its
    bytes escaped, or as `shown`), in LINE_WIDTH columns where the description allows."""
    head = f"{time:7.3f} {direction} "
    room = max(RAW_MIN, LINE_WIDTH - len(head) - 1 - len(text))
    if shown is None:
        shown = escape(raw)
    if len(shown) > room:
        shown = shown[: room - 1] + "…"
    return f"{head}{shown:<{min(RAW_WIDTH, max(room, len(shown)))}} {text}"


def params_table(
    values: tuple[int, ...],
    defaults: tuple[int, ...] = DEFAULTS,
    specs: param_values.Specs = param_values.SHEET,
) -> str:
    """The parameters as an aligned table, in the user's units, with their ranges and the
    board's defaults; a value outside its range (a real board may hold one) is flagged."""
    rows = [f"{'n':>2}  {'name':<18} {'value':>10}  {'range':<14} {'default':>7}"]
    for index, (spec, value, default) in enumerate(zip(specs, values, defaults, strict=True)):
        flag = "" if param_values.error(specs, index, value) is None else "  out of range"
        shown, usual = param_values.to_user(spec, value), param_values.to_user(spec, default)
        rows.append(
            f"{index:>2}  {spec.name:<18} {shown:>10}  "
            f"{param_values.range_text(spec):<14} {usual:>7}{flag}"
        )
    return "\n".join(rows)
