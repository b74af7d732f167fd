"""How a read or set of either port ends when it fails, and the rounds it has."""

from __future__ import annotations

from dataclasses import dataclass

TRIES = 5
"""Rounds a read or set has before it fails."""
AGREE = 2
"""Replies (or C records) that must agree before a value is taken: the line has no
checksum."""


@dataclass(frozen=True, slots=True)
class QueryFailed:
    text: str
