"""Transcripts, format v1 (docs/design.md): one protocol unit a line, `TIME DIR PAYLOAD`."""

from __future__ import annotations

import codecs
import itertools
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import BinaryIO

from appmode.errors import AppmodeError
from appmode.protocol.escaping import escape, unescape
from appmode.protocol.reader import (
    RECEIVED,
    RECEIVED2,
    RECEIVED_CHASSIS,
    SENT,
    SENT2,
    SENT_CHASSIS,
)

HEADER = "# appmode transcript v1"
SUFFIX = ".transcript"
MAX_TIME = 86400.0
"""The latest time a line may have: a day. Later is surely a mistake, and a run to it
could not finish."""
TIME_DIGITS = 4
"""A line's time is written to 0.1 ms."""
MAX_LINE = 64 * 1024
"""Bytes a line may have: a recorded line is one command or record, well under this."""
DIRECTIONS = (SENT, RECEIVED, SENT2, RECEIVED2, SENT_CHASSIS, RECEIVED_CHASSIS)
UART2_DIRECTIONS = (SENT2, RECEIVED2)
CHASSIS_DIRECTIONS = (SENT_CHASSIS, RECEIVED_CHASSIS)
"""A WHEELTEC board's chassis port (§15): its lines are hex pairs, always."""
HEX_DIRECTIONS = UART2_DIRECTIONS + CHASSIS_DIRECTIONS
HEX_LINE = re.compile(r"(?:[0-9A-F]{2}|\?\?)(?: (?:[0-9A-F]{2}|\?\?))*")
"""A UART2 line of bytes as hex pairs (`??`: any byte, in an expectation). A UART2 line
of any other form is APP text (escaped), as UART2 carries in APP mode (§12); a recorder
writes such text so that it never has this form."""


def uart2_payload(raw: bytes, text: bool) -> str:
    """A UART2 line's payload: hex pairs, or with `text` (APP mode) escaped text, with
    every byte as `\\xNN` where plain escaping would look like hex pairs."""
    if not text:
        return raw.hex(" ").upper()
    shown = escape(raw)
    if HEX_LINE.fullmatch(shown):
        return "".join(f"\\x{b:02x}" for b in raw)
    return shown


def uart2_bytes(payload: str) -> tuple[bytes, bytes] | None:
    """A hex UART2 payload as (bytes with 00 for `??`, mask with 00 where `??`), or None
    when it is text."""
    if not HEX_LINE.fullmatch(payload):
        return None
    pairs = payload.split(" ")
    data = bytes(0 if p == "??" else int(p, 16) for p in pairs)
    mask = bytes(0 if p == "??" else 0xFF for p in pairs)
    return data, mask


# ---------------------------------------------------------------- reading

DIRECTIVES = {
    "board": "the board under test: @board profile=sheet|minibalance|balance|NAME "
    "digest=… drive=omni|mecanum|diff|diff-gyro start=power-up",
    "tolerance": "how early or late a '<' line may be matched, in seconds: @tolerance 0.3",
    "strict": "@strict on: every record must match the next '<' line (none ignored)",
    "align": "@align: time the '<' lines after the next one from when it is matched",
    "recorded": "when the recording began (UTC): @recorded 2026-11-29T08:00:00.000000Z",
}


RECORDED_TIME = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{6}Z")
"""What `@recorded` takes: when the recording began, UTC, to the microsecond."""


@dataclass(frozen=True, slots=True)
class Entry:
    """One `TIME DIR PAYLOAD` line."""

    lineno: int
    time: float
    direction: str
    data: bytes
    text: str


@dataclass(frozen=True, slots=True)
class Directive:
    """One `@name args` line."""

    lineno: int
    name: str
    args: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class Comment:
    """One `# text` line (the first one after the header is the title)."""

    lineno: int
    text: str


Line = Entry | Directive | Comment
"""What a transcript's line is, blank lines and the header aside."""


@dataclass(frozen=True, slots=True)
class Transcript:
    path: str
    items: tuple[Entry | Directive, ...]
    title: str = ""
    """The first comment after the header: what the transcript checks."""
    warnings: tuple[str, ...] = ()
    """What was left out: a last line cut short."""

    @property
    def entries(self) -> list[Entry]:
        return [item for item in self.items if isinstance(item, Entry)]

    @property
    def duration(self) -> float:
        return max((e.time for e in self.entries), default=0.0)


class TranscriptError(AppmodeError):
    """A transcript line that cannot be read: the message gives file:line."""


def parse_transcript(text: str, path: str = "<transcript>") -> Transcript:
    """Read transcript text; TranscriptError names the file, the line and what is wrong.
    A last line with no newline that cannot be read is left out, with a warning."""
    # lines end at \n only: form feeds and U+2028 in comments do not shift line numbers
    lines = text.removeprefix("\ufeff").split("\n")  # a BOM some editors write
    last = len(lines)
    numbered = ((n, line.encode(), n < last) for n, line in enumerate(lines, start=1))
    return parse_lines(numbered, path)


def stream_lines(handle: BinaryIO, name: str) -> Iterator[tuple[int, bytes, bool]]:
    """A transcript's lines from an open stream, a line at a time, each at most
    MAX_LINE bytes: (line number, bytes, whether a newline ended it)."""
    for lineno in itertools.count(1):
        raw = handle.readline(MAX_LINE + 1)
        if not raw:
            return
        if len(raw) > MAX_LINE:
            raise TranscriptError(
                f"{name}:{lineno}: a line of over {MAX_LINE:,} bytes: not a transcript"
            )
        if lineno == 1:
            raw = raw.removeprefix(codecs.BOM_UTF8)
        yield lineno, raw.removesuffix(b"\n"), raw.endswith(b"\n")


def parse_lines(lines: Iterable[tuple[int, bytes, bool]], path: str) -> Transcript:
    """A Transcript of numbered lines (`stream_lines`); TranscriptError if one is bad."""
    items: list[Entry | Directive] = []
    warnings: list[str] = []
    title = ""
    for item in line_items(lines, path, warnings.append):
        if isinstance(item, Comment):
            title = title or item.text
        else:
            items.append(item)
    return Transcript(path, tuple(items), title, tuple(warnings))


def line_items(
    lines: Iterable[tuple[int, bytes, bool]], path: str, warn: Callable[[str], None]
) -> Iterator[Line]:
    """Each line's item (the first comment is the title)."""
    for lineno, raw, ended in lines:
        try:
            item = _item(raw, lineno, path)
        except TranscriptError as exc:
            if ended:
                raise
            warn(f"{exc}; it is the last line and has no end: cut short, left out")
            return
        if item is not None:
            yield item


def _item(raw: bytes, lineno: int, path: str) -> Line | None:
    where = f"{path}:{lineno}"
    try:
        line = raw.decode("utf-8").removesuffix("\r")
    except UnicodeDecodeError as exc:
        raise TranscriptError(
            f"{where}: not UTF-8 text (byte {exc.start + 1} of the line)"
        ) from None
    stripped = line.strip()
    if lineno == 1 and stripped.startswith("# appmode transcript") and stripped != HEADER:
        raise TranscriptError(
            f"{where}: {_cut(stripped[2:])!r} is not a version this appmode reads (it reads v1)"
        )
    if not stripped:
        return None
    if stripped.startswith("#"):
        return None if stripped == HEADER else Comment(lineno, stripped.lstrip("# ").strip())
    if stripped.startswith("@"):
        return parse_directive(stripped, lineno, where)
    return parse_entry(line.rstrip("\r\n"), lineno, where)


def parse_directive(text: str, lineno: int, where: str) -> Directive:
    """One `@name args` line; TranscriptError if no such directive."""
    name, *args = text.strip()[1:].split() or [""]
    if name not in DIRECTIVES:
        known = ", ".join(f"@{d}" for d in DIRECTIVES)
        raise TranscriptError(f"{where}: unknown directive @{_cut(name)} (known: {known})")
    if name == "recorded" and (len(args) != 1 or not RECORDED_TIME.fullmatch(args[0])):
        raise TranscriptError(
            f"{where}: @recorded takes a UTC time such as 2026-11-29T08:00:00.000000Z"
        )
    return Directive(lineno, name, tuple(args))


def time_text(time: float) -> str:
    """A line's time as the format writes it: to 0.1 ms, or every digit it has beyond."""
    text = f"{time:.{TIME_DIGITS}f}"
    return text if float(text) == time else repr(time)


def format_line(item: Line) -> str:
    """The text of one line (no newline), as `_item` reads it back."""
    if isinstance(item, Entry):
        return f"{time_text(item.time)} {item.direction} {item.text}"
    if isinstance(item, Directive):
        return " ".join(("@" + item.name, *item.args))
    return f"# {item.text}"


def _cut(text: str, limit: int = 60) -> str:
    """`text` for a message, cut short if long."""
    return text if len(text) <= limit else f"{text[:limit]}… ({len(text):,} chars)"


def parse_entry(line: str, lineno: int, where: str) -> Entry:
    """One `TIME DIR PAYLOAD` line; TranscriptError says what is wrong, at `where`."""
    parts = line.split(" ", 2)
    if len(parts) != 3 or not parts[2]:
        raise TranscriptError(
            f"{where}: expected 'TIME DIR PAYLOAD' (e.g. 0.050 > {{Q:P}}), got {_cut(line)!r}"
        )
    time_text, direction, payload = parts
    try:
        time = float(time_text) if time_text.isascii() else -1.0
    except ValueError:
        time = -1.0
    if not time >= 0:
        raise TranscriptError(f"{where}: time {_cut(time_text)!r} is not seconds >= 0")
    if time > MAX_TIME:
        raise TranscriptError(
            f"{where}: time {_cut(time_text)!r} is more than a day (seconds in 0–{MAX_TIME:g}): "
            "split the transcript"
        )
    if direction not in DIRECTIONS:
        raise TranscriptError(
            f"{where}: direction {_cut(direction)!r} must be '>' (host to board) or '<' "
            "(board to host) on the APP port, '2>' or '2<' on UART2, 'c>' or 'c<' on a "
            "chassis port"
        )
    hexed = uart2_bytes(payload) if direction in HEX_DIRECTIONS else None
    if direction in CHASSIS_DIRECTIONS and hexed is None:
        raise TranscriptError(
            f"{where}: {_cut(payload)!r} is not hex pairs (upper case, one space apart: "
            "7B 00 00 …), as a chassis port's lines are"
        )
    if direction in UART2_DIRECTIONS and hexed is None and " " in payload:
        raise TranscriptError(
            f"{where}: {_cut(payload)!r} is neither hex pairs (upper case, one space apart: "
            "FF FE 01 …) nor APP text (escaped, so it has no spaces)"
        )
    if hexed is not None:
        if direction in (SENT2, SENT_CHASSIS) and "??" in payload:
            raise TranscriptError(
                f"{where}: '??' matches a byte the board sends: not in a {direction} line"
            )
        return Entry(lineno, time, direction, hexed[0], payload)
    try:
        data = unescape(payload)
    except ValueError as exc:
        raise TranscriptError(f"{where}: {exc}") from None
    return Entry(lineno, time, direction, data, payload)
