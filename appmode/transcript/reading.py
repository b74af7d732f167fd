"""Transcript files read from disk: whole (`read_transcript`) or a line at a time in
constant memory (`iter_transcript`), in the format their first bytes tell, whatever
the file's name (`protocol.formats.READERS`: text, the grammar of
`protocol.transcript`, or MCAP)."""

from __future__ import annotations

import io
import os
from collections.abc import Callable, Iterator

from appmode.errors import AppmodeError
from appmode.protocol.formats import MAGIC_SIZE, READERS, Format, read_as
from appmode.protocol.transcript import (
    Comment,
    Directive,
    Entry,
    Line,
    Transcript,
)


def read_transcript(path: str | os.PathLike[str], name: str | None = None) -> Transcript:
    """Read a transcript file; TranscriptError (file:line, with `name` in place of the
    path if given) or AppmodeError if unreadable. Read a line at a time, each at most
    MAX_LINE bytes: a file that is no transcript (/dev/zero, a binary) fails at once. A
    last line cut short (a recording stopped by a full disk) is left out, with a warning
    in `warnings`."""
    shown = name or os.fspath(path)
    items: list[Entry | Directive] = []
    warnings: list[str] = []
    title = ""
    for item in iter_lines(path, warnings.append, shown):
        if isinstance(item, Comment):
            title = title or item.text
        else:
            items.append(item)
    return Transcript(shown, tuple(items), title, tuple(warnings))


def iter_transcript(
    path: str | os.PathLike[str], warn: Callable[[str], None], directives_only: bool = False
) -> Iterator[Entry | Directive]:
    """The lines of a transcript file one at a time, in constant memory, as
    `read_transcript` reads them; `warn` hears of a last line cut short. With
    `directives_only`, only the `@` lines are read (a quick first pass over a text)."""
    for item in iter_lines(path, warn, directives_only=directives_only):
        if not isinstance(item, Comment):
            yield item


def iter_lines(
    path: str | os.PathLike[str],
    warn: Callable[[str], None],
    name: str | None = None,
    directives_only: bool = False,
    partial: bool = False,
) -> Iterator[Line]:
    """Every line of a transcript or MCAP file, comments too, in constant memory; an
    MCAP file cut short is an error unless `partial` (then `warn` hears of it)."""
    shown = name or os.fspath(path)
    try:
        with open(path, "rb") as handle:
            yield from _items(handle, shown, warn, directives_only, partial)
    except OSError as exc:
        raise AppmodeError(f"cannot read transcript {shown}: {exc.strerror}") from None


def _items(
    handle: io.BufferedReader,
    name: str,
    warn: Callable[[str], None],
    directives_only: bool,
    partial: bool,
) -> Iterator[Line]:
    form = read_as(handle.peek(MAGIC_SIZE)[:MAGIC_SIZE], name)
    items = form.read(handle, name, warn, _ends_whole(handle, form), partial)
    if directives_only:
        return (item for item in items if isinstance(item, Directive))
    return items


def _ends_whole(handle: io.BufferedReader, form: Format) -> bool | None:
    """Whether the file ends with its format's magic, as a whole one does (None: a pipe,
    which cannot be looked at ahead)."""
    magic = next((m for m, f in READERS.items() if f is form), b"")
    if not handle.seekable():
        return None
    start = handle.tell()
    size = handle.seek(0, os.SEEK_END)
    handle.seek(max(0, size - len(magic)))
    ends = handle.read(len(magic)) == magic and size >= 2 * len(magic)
    handle.seek(start)
    return ends
