"""Words for people: a count with its noun."""

from __future__ import annotations

import textwrap


def counted(count: int, noun: str, plural: str | None = None) -> str:
    """`1 error`, `2 errors` (`plural` for nouns that do not take an s)."""
    return f"{count} {noun if count == 1 else plural or noun + 's'}"


def wrapped(text: str, width: int = 80, indent: str = "  ") -> str:
    """`text` in lines of at most `width` columns, whole words, the later lines indented."""
    return textwrap.fill(
        text,
        width,
        subsequent_indent=indent,
        break_long_words=False,
        break_on_hyphens=False,
    )
