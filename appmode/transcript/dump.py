"""`appmode dump`: a transcript decoded, an event a line (text, JSON or CSV); the decoding
that `plot` and `convert` read too."""

from __future__ import annotations

import csv
import json
import sys
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TextIO

from appmode.board.profiles import profile_named
from appmode.errors import AppmodeError, InvalidValue
from appmode.files import say_if_fifo
from appmode.protocol import app, chassis, control
from appmode.protocol.control_view import view
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.params import DriveType
from appmode.protocol.reader import RECEIVED, RECEIVED2, PortsReader
from appmode.protocol.render import json_keys, line, record_names
from appmode.protocol.transcript import DIRECTIONS, Directive, Entry
from appmode.transcript.matcher import (
    BoardNeeds,
    BytesPattern,
    Pattern,
    board_needs,
    parse_pattern,
)
from appmode.transcript.reading import iter_lines, iter_transcript

Decoded = (
    app.Event | Pattern | BytesPattern | control.HostEvent | control.BoardEvent | chassis.Event
)


def decoded(
    items: Iterable[Entry | Directive],
    drive: DriveType | None,
    path: str,
    layout: Layout = VELOCITY,
) -> Iterator[tuple[float, str, Decoded]]:
    """(time, direction, event) for every command, record, frame and reply of a
    transcript's lines; a `<` line with `*` or `LO..HI` fields (a `2<` line with `??`) is
    an expectation, not bytes. UART2 lines are read as the board the transcript describes
    reads them (`PortsReader`: its drive type, APP text while system_mode bit 7 is set)."""
    reader = PortsReader(drive=drive, layout=layout)
    last = dict.fromkeys(DIRECTIONS, 0.0)
    for entry in items:
        if not isinstance(entry, Entry):
            continue
        last[entry.direction] = entry.time
        if entry.direction == RECEIVED2 and "??" in entry.text:
            yield entry.time, RECEIVED2, BytesPattern(entry.data, b"", entry.text)
            continue
        try:
            pattern = parse_pattern(entry.text) if entry.direction == RECEIVED else None
        except InvalidValue as exc:
            raise AppmodeError(f"{path}:{entry.lineno}: {exc}") from None
        if pattern is not None and any(f is None or f[0] != f[1] for f in pattern.fields):
            yield entry.time, RECEIVED, pattern
            continue
        for direction, event in reader.feed(entry.direction, entry.data):
            yield entry.time, direction, event
    for direction, event in reader.flush():
        yield last[direction], direction, event


def needs_of(path: str, warn: Callable[[str], None], partial: bool = False) -> BoardNeeds:
    """The board a transcript file names (`@board`, the last one), read from its `@`
    lines alone (`partial`: of an MCAP file cut short too)."""
    needs = BoardNeeds()
    for item in iter_lines(path, warn, directives_only=True, partial=partial):
        if isinstance(item, Directive) and item.name == "board":
            needs = board_needs(item.args, f"{path}:{item.lineno}")
    return needs


def expectation_json(pattern: Pattern, layout: Layout = VELOCITY) -> dict[str, Any]:
    """An expectation as `to_json` shows records, `"*"` for a field that matches any and
    `"LO..HI"` for a range."""
    names = record_names(pattern.letter, layout)
    values: list[int | str] = [
        "*" if f is None else f[0] if f[0] == f[1] else f"{f[0]}..{f[1]}" for f in pattern.fields
    ]
    body: dict[str, Any] = {"kind": "expectation", "letter": pattern.letter}
    if len(names) == len(values):
        body.update(zip(names, values, strict=True))
    else:
        body["values"] = values
    return {**body, "raw": pattern.text}


def run_dump(
    path: str,
    fmt: str,
    out: TextIO,
    profile: str | None = None,
    only: tuple[str, ...] | None = None,
) -> int:
    """Print every event (`only` those of these directions); A records named as `profile`
    lays them out (default: the transcript's `@board profile=…`, else the sheet's)."""
    say_if_fifo(path)
    given = profile_named(profile) if profile else None  # a file the @board line may name
    needs = needs_of(path, lambda text: None)  # the second pass warns
    layout = (given or needs.profile).a_layout
    if fmt == "csv":
        fields = tuple(dict.fromkeys(("t", "dir", *json_keys(layout), *chassis.JSON_KEYS)))
        writer = csv.DictWriter(out, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
    items = iter_transcript(path, lambda text: print(f"appmode: WARNING: {text}", file=sys.stderr))
    for t, direction, event in decoded(items, needs.drive, path, layout):
        if only is not None and direction not in only:
            continue
        shown = None
        if isinstance(event, BytesPattern):
            body = {"kind": "expectation", "raw": event.text}
            raw, text = event.text.encode(), "expectation (?? matches any byte)"
            shown = event.text
        elif isinstance(event, Pattern):
            body = expectation_json(event, layout)
            raw = event.text.encode()
            text = "expectation " + " ".join(
                f"{k}={v}" for k, v in body.items() if k not in ("kind", "letter", "raw")
            )
        else:
            body, text, shown = view(event, layout)
            raw = event.raw
        if fmt == "json":
            out.write(json.dumps({"t": t, "dir": direction, **body}) + "\n")
        elif fmt == "csv":
            row = {k: ":".join(map(str, v)) if isinstance(v, list) else v for k, v in body.items()}
            writer.writerow({"t": t, "dir": direction, **row})
        else:
            out.write(line(t, direction, raw, text, shown) + "\n")
    return 0
