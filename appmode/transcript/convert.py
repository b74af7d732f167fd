"""`appmode convert IN OUT`: a transcript as MCAP and back, losslessly — every line's
time, direction and bytes (or pattern), its directives and comments, and its line
number (MCAP's sequence number; blank lines put a line back at its number). The MCAP
file adds the decoded channels viewers plot; reading it back skips them."""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator

from appmode.board.profiles import profile_named
from appmode.errors import AppmodeError
from appmode.files import check_writable, write_streamed
from appmode.protocol.layouts import Layout
from appmode.protocol.params import DriveType
from appmode.protocol.reader import PortsReader
from appmode.protocol.transcript import HEADER, Entry, Line, format_line
from appmode.transcript.dump import needs_of
from appmode.transcript.reading import iter_lines

PAD = 100
"""Blank lines at most that put a line back at its number (a larger gap is closed)."""


def run_convert(source: str, output: str, profile: str | None, partial: bool) -> int:
    """Write `source` (a transcript or MCAP) to `output`, as MCAP when its name ends in
    `.mcap`, else as a transcript; the decoded channels in `profile`'s terms (default:
    the source's `@board profile=…`)."""
    if _same_file(source, output):
        raise AppmodeError(f"convert: {output} is the file being read; name another output")
    check_writable(output, "the converted file")

    def warn(text: str) -> None:
        print(f"appmode: WARNING: {text}", file=sys.stderr)

    given = profile_named(profile) if profile else None  # a file the @board line may name
    needs = needs_of(source, lambda text: None, partial=partial)
    layout = (given or needs.profile).a_layout
    items = iter_lines(source, warn, partial=partial)
    to_mcap = output.lower().endswith(".mcap")
    counted: list[int] = []
    chunks = _as_mcap(items, layout, needs.drive, counted) if to_mcap else _as_text(items, counted)
    write_streamed(output, chunks, "the converted file")
    kind = "MCAP" if to_mcap else "transcript"
    print(
        f"convert: {len(counted)} lines of {source} written to {output} ({kind})", file=sys.stderr
    )
    return 0


def _same_file(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _as_text(items: Iterator[Line], counted: list[int]) -> Iterator[bytes]:
    yield (HEADER + "\n").encode()
    at = 1
    for item in items:
        counted.append(item.lineno)
        gap = item.lineno - at - 1
        if 0 < gap <= PAD:
            yield b"\n" * gap
            at += gap
        at += 1
        yield (format_line(item) + "\n").encode()


def _as_mcap(
    items: Iterator[Line], layout: Layout, drive: DriveType | None, counted: list[int]
) -> Iterator[bytes]:
    try:
        from appmode.protocol.mcap_format import McapLines, is_pattern
    except ImportError:
        raise AppmodeError(
            "writing MCAP needs the mcap package: pip install 'appmode[foxglove]'"
        ) from None
    lines = McapLines(layout, library="appmode convert")
    reader = PortsReader(drive=drive, layout=layout)
    yield lines.start()
    time = 0.0
    for item in items:
        counted.append(item.lineno)
        if isinstance(item, Entry):
            time = item.time
        yield lines.item(item, time)
        if isinstance(item, Entry) and not is_pattern(item):
            for direction, event in reader.feed(item.direction, item.data):
                yield lines.decoded(item.time, direction, event)
    for direction, event in reader.flush():
        yield lines.decoded(time, direction, event)
    yield lines.finish()
