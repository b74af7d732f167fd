"""The names of the board profiles (board/profiles.py holds the profiles; it checks that
they are these): what the command line offers without loading them."""

from __future__ import annotations

PROFILE_NAMES: tuple[str, ...] = ("sheet", "minibalance")
