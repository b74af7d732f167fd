"""Testing host code against appmode's simulated board.

The pytest plugin (`plugin.py`, registered as a `pytest11` entry point) gives the
`appmode_board`, `appmode_board_factory` and `appmode_sim_url` fixtures; `served.py`
the board they serve (`ServedBoard`, usable without pytest too). `assert_conforms` checks
a board's recording against a transcript's expectations.
"""

from __future__ import annotations

from pathlib import Path
from typing import Protocol


class Recorded(Protocol):
    def assert_conforms(self, expected: str | Path) -> None: ...


def assert_conforms(board: Recorded, expected: str | Path) -> None:
    """AssertionError, with the conformance runner's message, unless what `board` has
    recorded so far meets the expectations of the transcript file `expected`."""
    __tracebackhide__ = True
    board.assert_conforms(expected)
