"""The documents stay true: docs/api.md's examples run, and no document sends a reader
to a file outside the repository."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_api_examples_run() -> None:
    result = doctest.testfile(str(ROOT / "docs" / "api.md"), module_relative=False)
    assert result.attempted > 5
    assert result.failed == 0


def test_protocol_reference_is_in_the_repository() -> None:
    texts = [ROOT / "README.md", *ROOT.joinpath("docs").glob("*.md")]
    package = ROOT / "appmode"
    texts += [*package.rglob("*.py"), *ROOT.joinpath("transcripts").rglob("*.transcript")]
    for path in texts:
        text = path.read_text(encoding="utf-8")
        assert "shared/" not in text, f"{path} points outside the repository"
        assert not re.search(r"(?<![\w/])protocol\.md", text), f"{path}: say docs/protocol.md"
    assert (ROOT / "docs" / "protocol.md").is_file()
    assert "[docs/protocol.md](docs/protocol.md)" in (ROOT / "README.md").read_text()
