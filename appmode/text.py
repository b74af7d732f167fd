"""Words for people: a count with its noun, text wrapped to a width, and text from
outside (a device's name, a profile's labels, a board's bytes) made safe to show."""

from __future__ import annotations

import re

from appmode.patterns import deferred

_UNSAFE = deferred(r"[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028-\u202e\u2066-\u2069]")
"""What a terminal or a page would act on rather than show: C0 and C1 controls (ESC
starts a terminal's commands: colours, the clipboard, the title, erasing a line), DEL,
the line and paragraph separators, and the bidirectional marks and overrides that
reorder what follows."""


def escaped(text: str) -> str:
    """`text` with every control character written as an escape (`\\x1b`, `\\u202e`): what
    came from outside is shown as what it is, never acted on."""
    return _UNSAFE.sub(_escape, text)


def _escape(found: re.Match[str]) -> str:
    code = ord(found[0])
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


LONGEST_WORD = 120
"""The longest run of characters without a space an error message shows whole."""
_LONG_WORD = deferred(rf"\S{{{LONGEST_WORD + 1},}}")


def shortened(text: str) -> str:
    """`text` with every word longer than LONGEST_WORD cut to its start and its length:
    a 10 kB URL is named in an error, not echoed."""
    return _LONG_WORD.sub(lambda m: f"{m[0][:60]}…({len(m[0]):,} characters)", text)


def counted(count: int, noun: str, plural: str | None = None) -> str:
    """`1 error`, `2 errors` (`plural` for nouns that do not take an s)."""
    return f"{count} {noun if count == 1 else plural or noun + 's'}"


def wrapped(text: str, width: int = 80, indent: str = "  ") -> str:
    """`text` in lines of at most `width` columns, whole words, the later lines indented."""
    import textwrap  # here: start-up

    return textwrap.fill(
        text,
        width,
        subsequent_indent=indent,
        break_long_words=False,
        break_on_hyphens=False,
    )
