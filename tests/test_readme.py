"""The README stays true: its parameter table is the code's table."""

from __future__ import annotations

import re
from pathlib import Path

from appmode.protocol import params

README = Path(__file__).resolve().parent.parent / "README.md"


def test_readme_parameter_table_matches_params() -> None:
    rows = re.findall(r"^\| (\d) \| (\w+) \| (\d+)–(\d+) \| (\d+) \|$", README.read_text(), re.M)
    assert rows == [
        (str(p.index), p.name, str(p.minimum), str(p.maximum), str(p.default))
        for p in params.PARAMS
    ]


def test_readme_opens_with_two_setup_commands() -> None:
    block = re.search(r"```sh\n(.*?)```", README.read_text(), re.S)
    assert block is not None
    assert block.group(1).splitlines() == [
        "pip install . && appmode drive",
        "pip install '.[test]' && pytest",
    ]


def test_the_headings_appmode_points_at_are_in_the_readme() -> None:
    """Issue 23.5: the `ports` hint pointed at a heading that does not exist."""
    lines = README.read_text().splitlines()
    headings = {line.lstrip("#").strip() for line in lines if line.startswith("#")}
    for path in (README.parent / "appmode").rglob("*.py"):
        for name in re.findall(r"see '([^']+)' in the README", path.read_text()):
            assert name in headings, f"{path}: no heading {name!r} in the README"
