"""Transcript files read from disk: whole (`read_transcript`) or a line at a time in
constant memory (`iter_transcript`). The grammar is `protocol.transcript`'s, which reads
only what it is given."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator

from appmode.errors import AppmodeError
from appmode.protocol.transcript import (
    Directive,
    Entry,
    Transcript,
    line_items,
    parse_lines,
    stream_lines,
)


def read_transcript(path: str | os.PathLike[str], name: str | None = None) -> Transcript:
    """Read a transcript file; TranscriptError (file:line, with `name` in place of the
    path if given) or AppmodeError if unreadable. Read a line at a time, each at most
    MAX_LINE bytes: a file that is no transcript (/dev/zero, a binary) fails at once. A
    last line cut short (a recording stopped by a full disk) is left out, with a warning
    in `warnings`."""
    name = name or os.fspath(path)
    try:
        with open(path, "rb") as handle:
            return parse_lines(stream_lines(handle, name), name)
    except OSError as exc:
        raise AppmodeError(f"cannot read transcript {name}: {exc.strerror}") from None


def iter_transcript(
    path: str | os.PathLike[str], warn: Callable[[str], None], directives_only: bool = False
) -> Iterator[Entry | Directive]:
    """The lines of a transcript file one at a time, in constant memory, as
    `read_transcript` reads them; `warn` hears of a last line cut short. With
    `directives_only`, only the `@` lines are read (a quick first pass)."""
    name = os.fspath(path)
    try:
        with open(path, "rb") as handle:
            lines = stream_lines(handle, name)
            if directives_only:
                lines = (line for line in lines if line[1].lstrip().startswith(b"@"))
            for item in line_items(lines, name, warn):
                if not isinstance(item, str):
                    yield item
    except OSError as exc:
        raise AppmodeError(f"cannot read transcript {name}: {exc.strerror}") from None
