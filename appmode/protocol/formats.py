"""The recording formats, in one table each way as python-can keeps its message writers
and readers: a file's name chooses how it is written (`WRITERS`, by suffix; a
transcript unless the suffix names another), its first bytes how it is read
(`READERS`, by magic; a transcript when none fits). No I/O: a format writes the lines a
recorder or `convert` hands it, and reads from a stream it is handed. A new format is a
`Format` and a row in each table."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator
from typing import BinaryIO

from appmode.errors import AppmodeError, install_line
from appmode.protocol.layouts import Layout
from appmode.protocol.params import DriveType
from appmode.protocol.reader import PortsReader
from appmode.protocol.recorder import Lines, TextLines
from appmode.protocol.transcript import (
    HEADER,
    SUFFIX,
    Directive,
    Entry,
    Line,
    format_line,
    line_items,
    stream_lines,
)

Warn = Callable[[str], None]
PAD = 100
"""Blank lines at most that put a converted line back at its number (a larger gap is
closed)."""
MCAP_MAGIC = b"\x89MCAP0\r\n"
MAGIC_SIZE = len(MCAP_MAGIC)
"""Bytes a reader looks at to tell the format."""


class Format:
    """How one format is written and read."""

    name = ""
    suffix = ""
    binary = False
    """Its files are bytes (else UTF-8 text)."""

    def lines(self, layout: Layout) -> Lines:
        """What a recorder writes: its start, each unit, its end."""
        raise NotImplementedError

    def convert(
        self, items: Iterator[Line], layout: Layout, drive: DriveType | None, counted: list[int]
    ) -> Iterator[bytes]:
        """The file's bytes for transcript lines (`convert`), each line's number put in
        `counted` as it goes."""
        raise NotImplementedError

    def read(
        self, handle: BinaryIO, name: str, warn: Warn, whole: bool | None, partial: bool
    ) -> Iterator[Line]:
        """The lines a file holds (`whole`: whether it ends as a file of its format
        ends, None: not known, a pipe; `partial`: a file cut short gives what it holds,
        and `warn` says so)."""
        raise NotImplementedError


class Text(Format):
    """A transcript, format v1: UTF-8 text, a line a unit."""

    name, suffix = "transcript", SUFFIX

    def lines(self, layout: Layout) -> Lines:
        return TextLines()

    def convert(
        self, items: Iterator[Line], layout: Layout, drive: DriveType | None, counted: list[int]
    ) -> Iterator[bytes]:
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

    def read(
        self, handle: BinaryIO, name: str, warn: Warn, whole: bool | None, partial: bool
    ) -> Iterator[Line]:
        return line_items(stream_lines(handle, name), name, warn)


class Mcap(Format):
    """MCAP (`mcap_format`): the lines as raw channels, with the decoded channels
    viewers plot; needs the foxglove extra's mcap package."""

    name, suffix, binary = "MCAP", ".mcap", True

    def lines(self, layout: Layout) -> Lines:
        try:
            from appmode.protocol.mcap_format import McapLines
        except ImportError:
            raise _missing("writing MCAP") from None
        return McapLines(layout)

    def convert(
        self, items: Iterator[Line], layout: Layout, drive: DriveType | None, counted: list[int]
    ) -> Iterator[bytes]:
        try:
            from appmode.protocol.mcap_format import McapLines, is_pattern
        except ImportError:
            raise _missing("writing MCAP") from None
        items, start_ns = _recorded(items)
        lines = McapLines(layout, library="appmode convert", start_ns=start_ns)
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

    def read(
        self, handle: BinaryIO, name: str, warn: Warn, whole: bool | None, partial: bool
    ) -> Iterator[Line]:
        try:
            from appmode.protocol.mcap_reading import read_items
        except ImportError:
            raise _missing(f"{name} is MCAP: reading it") from None
        return read_items(handle, name, warn, whole, partial)


def _recorded(items: Iterator[Line]) -> tuple[Iterator[Line], int]:
    """When the transcript was recorded (its `@recorded`, before its first entry), in ns
    since 1970 (0: it does not say), and its lines, all of them."""
    from appmode.protocol.mcap_format import RECORDED, start_of

    head: list[Line] = []
    start = 0
    for item in items:
        head.append(item)
        if isinstance(item, Directive) and item.name == RECORDED:
            start = start_of(" ".join(item.args), f"line {item.lineno}")
        if isinstance(item, Entry):
            break
    return itertools.chain(head, items), start


def _missing(doing: str) -> AppmodeError:
    """What to install to do what needs the mcap package."""
    return AppmodeError(f"{doing} needs the mcap package: {install_line('foxglove')}")


TEXT, MCAP = Text(), Mcap()
WRITERS: dict[str, Format] = {TEXT.suffix: TEXT, MCAP.suffix: MCAP}
"""How a file is written, by its name's suffix (lower case)."""
READERS: dict[bytes, Format] = {MCAP_MAGIC: MCAP}
"""How a file is read, by its first bytes (else as a transcript)."""


def written_as(name: str) -> Format:
    """The format a file of this name is written in."""
    base = name.replace("\\", "/").rsplit("/", 1)[-1]
    return WRITERS.get(base[base.rfind(".") :].lower() if "." in base else "", TEXT)


def read_as(first: bytes, name: str = "") -> Format:
    """The format of a file named `name` that begins with `first` (MAGIC_SIZE bytes, or
    fewer): the one its name's suffix says (a `.mcap` file is read as MCAP, whatever its
    first bytes), else the one whose magic it begins with, or with part of (a file cut
    short); else a transcript."""
    suffixed = WRITERS.get("." + name.rpartition(".")[2].lower()) if "." in name else None
    if suffixed is not None and suffixed is not TEXT:
        return suffixed
    for magic, form in READERS.items():
        if first.startswith(magic) or (first and magic.startswith(first)):
            return form
    return TEXT
