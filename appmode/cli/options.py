"""Arguments that several commands share."""

from __future__ import annotations

import argparse
from typing import TypeAlias

URL_FORMS = (
    "the board: /dev/ttyUSB0, /dev/rfcomm0, COM3 (?baud=N), socket://HOST:PORT, "
    "rfc2217://HOST:PORT, loop:// or sim:// (the simulated board)"
)


def add_url(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("url", metavar="URL", help=URL_FORMS)


def add_record(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--record", metavar="FILE", help="record the session as a transcript (flushed line by line)"
    )


Subparsers: TypeAlias = "argparse._SubParsersAction[argparse.ArgumentParser]"
"""What `add_subparsers()` returns."""
