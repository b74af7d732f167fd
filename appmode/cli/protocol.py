"""`appmode protocol [SECTION]`: the protocol reference that ships with appmode, whole or
a section at a time (the messages that cite `§8.3` point here)."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers
from appmode.errors import AppmodeError

HEADING = re.compile(r"(#+) (?:Part ([IVX]+)\b|(\d+(?:\.\d+)*)\.?(?= ))")
"""A heading that opens a numbered section (`## 8.`, `### 8.3`) or a part (`# Part II`)."""


REFERENCE = "docs/protocol.md"
"""Where the reference is: in the package of an installed wheel (the build maps the
repository's file there), else in the checkout appmode runs from."""


def reference() -> Path:
    """The protocol reference that ships with appmode."""
    package = Path(__file__).parents[1]
    installed = package / REFERENCE
    return installed if installed.is_file() else package.parent / REFERENCE


def register(sub: Subparsers) -> argparse.ArgumentParser:
    parser = sub.add_parser(
        "protocol",
        help=COMMANDS["protocol"],
        description="Print the protocol reference that ships with appmode (both ports, "
        "every decision where the vendor's sheet is wrong or silent, the real firmware as "
        "measured): its contents with no SECTION, else that section with its subsections.",
    )
    parser.add_argument(
        "section",
        nargs="?",
        metavar="SECTION",
        help="a section number as messages cite it (8.3, §8.3) or a part (II, 'Part II')",
    )
    parser.add_argument("--all", action="store_true", help="print the whole reference")
    return parser


def _key(text: str) -> str:
    """A section as given (`§8.3`, `8.3.`, `part ii`) in the form its heading has."""
    key = text.strip().removeprefix("§").rstrip(".").strip()
    part = re.fullmatch(r"(?i)(?:part\s+)?([ivx]+)", key)
    return f"Part {part.group(1).upper()}" if part else key


def _sections(lines: list[str]) -> list[tuple[int, int, str]]:
    """(line index, heading level, key) of every numbered heading, outside code blocks."""
    found, block = [], False
    for index, line in enumerate(lines):
        if line.startswith("```"):
            block = not block
        elif not block and (m := HEADING.match(line)):
            found.append(
                (index, len(m.group(1)), f"Part {m.group(2)}" if m.group(2) else m.group(3))
            )
    return found


def run(args: argparse.Namespace) -> int:
    try:
        lines = reference().read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise AppmodeError(
            f"cannot read the protocol reference {reference()}: {exc.strerror or exc}: "
            "reinstall appmode"
        ) from None
    sections = _sections(lines)
    if args.all:
        chosen = lines
    elif args.section is None:
        chosen = [lines[0], ""] + [
            "  " * (level - 1) + lines[index].lstrip("# ") for index, level, _ in sections
        ]
        chosen += ["", "appmode protocol SECTION prints one (8.3, II); --all prints it whole"]
    else:
        key = _key(args.section)
        match = [(index, level) for index, level, name in sections if name == key]
        while not match and "." in key:  # §13.1 is told within §13
            key = key.rsplit(".", 1)[0]
            match = [(index, level) for index, level, name in sections if name == key]
        if not match:
            numbers = [name for _, level, name in sections if level == 2]
            raise AppmodeError(
                f"no section {args.section!r} in the protocol reference: its sections are "
                f"{numbers[0]}–{numbers[-1]} and their subsections (appmode protocol lists them)"
            )
        start, level = match[0]
        end = next((i for i, lv, _ in sections if i > start and lv <= level), len(lines))
        chosen = lines[start:end]
    sys.stdout.write("\n".join(chosen).rstrip("\n") + "\n")
    return 0
