"""`appmode dump` and `appmode plot`: decode a transcript, and draw its telemetry."""

from __future__ import annotations

import csv
import json
import re
import sys
import textwrap
from collections.abc import Callable, Iterable, Iterator
from io import BytesIO
from pathlib import Path
from typing import Any, TextIO

from appmode.board.profiles import profile_named
from appmode.errors import AppmodeError, InvalidValue
from appmode.files import check_writable, say_if_fifo, write_whole
from appmode.protocol import app, control
from appmode.protocol.control_view import view
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.params import DriveType
from appmode.protocol.reader import RECEIVED, RECEIVED2, SENT2, PortsReader
from appmode.protocol.render import json_keys, line, record_names
from appmode.protocol.transcript import DIRECTIONS, Directive, Entry, Transcript
from appmode.transcript.matcher import (
    BoardNeeds,
    BytesPattern,
    Check,
    Pattern,
    board_needs,
    parse_pattern,
)
from appmode.transcript.reading import iter_lines, iter_transcript, read_transcript

Decoded = app.Event | Pattern | BytesPattern | control.HostEvent | control.BoardEvent


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


def run_dump(path: str, fmt: str, out: TextIO, profile: str | None = None) -> int:
    """Print every event; A records named as `profile` lays them out (default: the
    transcript's `@board profile=…`, else the sheet's)."""
    say_if_fifo(path)
    needs = needs_of(path, lambda text: None)  # the second pass warns
    layout = (profile_named(profile) if profile else needs.profile).a_layout
    if fmt == "csv":
        fields = ("t", "dir", *json_keys(layout))
        writer = csv.DictWriter(out, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
    items = iter_transcript(path, lambda text: print(f"appmode: WARNING: {text}", file=sys.stderr))
    for t, direction, event in decoded(items, needs.drive, path, layout):
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


LABEL_GAP = 0.012
"""Fraction of the time axis two command labels need between them (8 pt text, 11 in)."""


def command_labels(commands: list[tuple[float, str]], gap: float) -> list[tuple[float, str]]:
    """One label per group of commands closer than `gap` seconds: their texts joined,
    at the first one's time, so that labels never overlap."""
    groups: list[tuple[float, list[str]]] = []
    for t, text in commands:
        if groups and t - groups[-1][0] < gap:
            groups[-1][1].append(text)
        else:
            groups.append((t, [text]))
    labels = []
    for t, texts in groups:
        label = " ".join(texts)
        labels.append((t, label if len(label) <= 16 else label[:15] + "…"))
    return labels


VELOCITY_LABELS = ("x (lateral, right +)", "y (forward +)", "z (rotation, cw +)", "extra")


def run_plot(path: str, output: str, profile: str | None = None) -> int:
    """Velocities, attitude and battery over time, with the commands marked; the fields
    named as `profile` lays them out (default: the transcript's `@board profile=…`)."""
    check_writable(output, "plot")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import MaxNLocator
    except ImportError:
        raise AppmodeError(
            "appmode plot needs matplotlib: pip install matplotlib (or, in a checkout of "
            "appmode, pip install '.[plot]')"
        ) from None
    transcript = read_transcript(path)
    for warning in transcript.warnings:
        print(f"appmode: WARNING: {warning}", file=sys.stderr)
    needs = Check(transcript).needs
    layout = (profile_named(profile) if profile else needs.profile).a_layout
    a, b, commands = _series(transcript, path, layout)
    if not a and not b:
        return _plot_reports(plt, transcript, path, output)
    fig, (strip, vel, att, bat) = plt.subplots(
        4, 1, sharex=True, figsize=(11, 8.5), height_ratios=(0.7, 3, 3, 2), layout="constrained"
    )
    names = VELOCITY_LABELS if layout is VELOCITY else layout.labels
    ta = [t for t, _ in a]
    for i in layout.motion:
        vel.plot(ta, [v[i] for _, v in a], label=names[i], drawstyle="steps-post")
    unit = layout.a_fields[layout.motion[0]].unit if layout.motion else ""
    scaled = f"{layout.scale:g}·" if layout.scale != 1 else ""
    wraps = layout.a_fields[layout.motion[0]].wrap if layout.motion else None
    vel.set_ylabel(
        f"{unit or 'value'}"
        if layout.signed
        else f"|{scaled}v| ({unit})" + (f", wraps at {wraps}" if wraps else "")
    )
    tb = [t for t, _ in b]
    shown = [(i, f) for i, f in enumerate(layout.b_fields) if not f.battery]
    for i, field in shown:
        att.plot(tb, [v[i] for _, v in b], label=field.label, drawstyle="steps-post")
    words = {"°": "degrees", "": "value"}
    att.set_ylabel(" / ".join(dict.fromkeys(words.get(f.unit, f.unit) for _, f in shown)))
    times, battery = _battery(layout, a, b)
    bat.plot(times, battery, color="tab:green", drawstyle="steps-post")
    bat.set_ylabel("battery %")
    if battery:  # the range it spans, so that a change shows
        low, high = min(battery), max(battery)
        pad = max(2.0, (high - low) * 0.1)
        bat.set_ylim(low - pad, high + pad)
        bat.yaxis.set_major_locator(MaxNLocator(integer=True))
    bat.set_xlabel("time (s)")
    every = ta + tb + [t for t, _ in commands]
    _mark_commands(strip, (vel, att, bat), commands, max(every) - min(every))
    vel.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    att.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.suptitle(_title(path, transcript), fontsize=11)
    return _save(plt, fig, output)


Series = list[tuple[float, tuple[int, ...]]]
"""(time, a record's values), in order."""


def _battery(layout: Layout, a: Series, b: Series) -> tuple[list[float], list[int]]:
    """The battery over time, from the B record's battery field, else the A record's."""
    held = next((i for i, f in enumerate(layout.b_fields) if f.battery), None)
    if held is not None:
        return [t for t, _ in b], [v[held] for _, v in b]
    if layout.battery is not None:
        return [t for t, _ in a], [v[layout.battery] for _, v in a]
    return [], []


def _title(path: str, transcript: Transcript) -> str:
    """The file's name and the transcript's title, whole words in lines that fit."""
    title = (transcript.title or "telemetry").rstrip(",;: ")
    return textwrap.fill(f"{Path(path).name} — {title}", 110)


def _mark_commands(strip: Any, axes: tuple[Any, ...], commands: list[Any], span: float) -> None:
    """The commands sent: a dotted line on each plot, their labels in a strip of their
    own above (never over the data)."""
    strip.axis("off")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        for t, _ in commands:
            ax.axvline(t, color="grey", linestyle=":", linewidth=0.8)
    for t, text in command_labels(commands, span * LABEL_GAP):
        strip.annotate(
            text,
            (t, 0.0),
            xycoords=("data", "axes fraction"),
            fontsize=8,
            rotation=90,
            va="bottom",
            ha="center",
            color="dimgrey",
        )


def _plot_reports(plt: Any, transcript: Transcript, path: str, output: str) -> int:
    """A UART2 transcript: each wheel's target (dashed) and actual speed from the encoder
    reports (§12), the frames sent marked."""
    reports: list[tuple[float, control.EncoderReport]] = []
    frames: list[tuple[float, str]] = []
    for t, direction, event in decoded(transcript.items, Check(transcript).needs.drive, path):
        if isinstance(event, control.EncoderReport):
            reports.append((t, event))
        elif direction == SENT2 and not isinstance(event, control.ERRORS):
            kind = type(event).__name__.removesuffix("Frame")
            frames.append((t, re.sub(r"(?<!^)(?=[A-Z])", " ", kind).lower()))
    if not reports:
        raise AppmodeError(
            f"{path} has no A or B records, and no encoder reports (UART2, §12), to plot"
        )
    fig, (strip, wheels) = plt.subplots(
        2, 1, sharex=True, figsize=(11, 6), height_ratios=(0.8, 4), layout="constrained"
    )
    times = [t for t, _ in reports]
    for i in range(len(reports[0][1].actuals)):
        line = wheels.plot(times, [r.actuals[i] for _, r in reports], label=f"wheel {'ABCD'[i]}")
        wheels.plot(
            times, [r.targets[i] for _, r in reports], linestyle="--", color=line[0].get_color()
        )
    wheels.set_ylabel("wheel speed (dashed: target)")
    wheels.set_xlabel("time (s)")
    wheels.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    span = max(times + [t for t, _ in frames]) - min(times + [t for t, _ in frames])
    _mark_commands(strip, (wheels,), frames, span)
    fig.suptitle(_title(path, transcript), fontsize=11)
    return _save(plt, fig, output)


def _save(plt: Any, fig: Any, output: str) -> int:
    """Write the figure as a PNG, whole or not at all."""
    image = BytesIO()
    try:
        fig.savefig(image, format="png", dpi=110)
    finally:
        plt.close(fig)
    write_whole(output, image.getvalue(), "plot")
    return 0


def _series(
    transcript: Transcript, path: str, layout: Layout
) -> tuple[Series, Series, list[tuple[float, str]]]:
    """What a plot draws: the A and B records (time, values) as `layout` counts their
    fields, and the commands sent (time, text)."""
    needs = Check(transcript).needs
    a: Series = []
    b: Series = []
    commands: list[tuple[float, str]] = []
    for t, direction, event in decoded(transcript.items, needs.drive, path, layout):
        if isinstance(event, (app.Velocity, app.Attitude, app.OtherRecord)):
            letter, values = app.record_fields(event)
            if letter == "A":
                a.append((t, values))
            elif letter == "B" and len(values) == len(layout.b_fields):
                b.append((t, values))
        elif direction == ">" and isinstance(event, app.Command):
            commands.append((t, event.raw.decode("latin-1")))
    return a, b, commands
