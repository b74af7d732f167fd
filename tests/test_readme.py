"""The README and the documents stay true: the parameter table is the code's table, and
the README stays a front door."""

from __future__ import annotations

import re
from pathlib import Path

from appmode.protocol import params

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"


def test_the_parameter_table_matches_params() -> None:
    decisions = (ROOT / "docs" / "decisions.md").read_text()
    rows = re.findall(r"^\| (\d) \| (\w+) \| (\d+)–(\d+) \| (\d+) \|$", decisions, re.M)
    assert rows == [
        (str(p.index), p.name, str(p.minimum), str(p.maximum), str(p.default))
        for p in params.PARAMS
    ]


def test_readme_opens_with_two_setup_commands() -> None:
    block = re.search(r"```sh\n(.*?)```", README.read_text(), re.S)
    assert block is not None
    assert block.group(1).splitlines() == [
        "pip install '.[web]' && appmode drive",
        "pip install '.[test]' && pytest",
    ]


def test_readme_fits_on_a_screen_and_links_into_the_docs() -> None:
    """Issue 52.1: at most 250 lines, and every document it links to is there."""
    text = README.read_text()
    assert len(text.splitlines()) <= 250
    links = re.findall(r"\]\(((?:docs/)?[\w/.-]+\.(?:md|png|svg))\)", text)
    assert len(links) > 10
    missing = [link for link in links if not (ROOT / link).is_file()]
    assert not missing, f"the README links to documents that are not there: {missing}"
