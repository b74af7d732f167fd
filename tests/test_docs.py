"""The documents stay true: docs/api.md's examples run, and no document sends a reader
to a file outside the repository."""

from __future__ import annotations

import doctest
import importlib
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_api_examples_run() -> None:
    result = doctest.testfile(str(ROOT / "docs" / "api.md"), module_relative=False)
    assert result.attempted > 5
    assert result.failed == 0


def test_protocol_reference_is_in_the_repository() -> None:
    texts = [ROOT / "README.md", *ROOT.joinpath("docs").rglob("*.md")]
    package = ROOT / "appmode"
    texts += [*package.rglob("*.py"), *ROOT.joinpath("transcripts").rglob("*.transcript")]
    for path in texts:
        text = path.read_text(encoding="utf-8")
        assert "shared/" not in text, f"{path} points outside the repository"
        if ROOT / "docs" in path.parents:  # a page of the site links to its neighbours
            continue
        assert not re.search(r"(?<![\w/])protocol\.md", text), f"{path}: say docs/protocol.md"
    assert (ROOT / "docs" / "protocol.md").is_file()
    assert "](docs/protocol.md)" in (ROOT / "README.md").read_text()


CITED = re.compile(
    r"`((?:protocol|board|line|ports|host|transcript|session|console|testing|cli)\.[A-Za-z_][\w.]*)`"
)


def _resolves(dotted: str) -> bool:
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            thing: object = importlib.import_module("appmode." + ".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            if not hasattr(thing, name):
                return False
            thing = getattr(thing, name)
        return True
    return False


def test_the_code_the_documents_name_exists() -> None:
    """The decision table and the design notes name modules and classes: they exist."""
    for doc in (ROOT / "docs" / "decisions.md", ROOT / "docs" / "design.md"):
        cited = set(CITED.findall(doc.read_text(encoding="utf-8")))
        assert len(cited) > 10
        missing = sorted(name for name in cited if not _resolves(name))
        assert not missing, f"{doc.name} names code that is not there: {missing}"


def test_design_notes_are_cited_where_they_are() -> None:
    """Modules and tests that cite the design notes point at docs/design.md."""
    assert (ROOT / "docs" / "design.md").is_file()
    for path in [*ROOT.joinpath("appmode").rglob("*.py"), *ROOT.joinpath("tests").rglob("*.py")]:
        if path == Path(__file__).resolve():
            continue  # this test names the file it looks for
        text = path.read_text(encoding="utf-8")
        assert not re.search(r"(?<![\w/])design\.md", text), f"{path}: say docs/design.md"
