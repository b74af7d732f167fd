"""Issue 52.3: the protocol reference ships with appmode, and what cites it names a
place a user has (`appmode protocol 8.3`), not a path in the repository."""

from __future__ import annotations

import ast
from pathlib import Path

from tests.support.processes import ROOT, run
from tests.support.source import parsed


def test_a_section_is_printed_with_its_subsections_and_no_more() -> None:
    done = run("protocol", "§8.3")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("### 8.3 Who drives")
    assert not any(line.startswith("## 9.") for line in lines)
    part = run("protocol", "part ii").stdout.splitlines()
    assert part[0].startswith("# Part II") and any(line.startswith("## 12.") for line in part)
    assert not any(line.startswith("# Part III") for line in part)


def test_the_contents_name_every_section_and_how_to_read_one() -> None:
    done = run("protocol")
    assert done.returncode == 0
    assert "  8. Link, frames and who drives" in done.stdout
    assert "    8.3 Who drives: the take-over" in done.stdout
    assert "appmode protocol SECTION prints one" in done.stdout


def test_a_subsection_without_a_heading_is_told_within_its_section() -> None:
    assert run("protocol", "13.1").stdout.startswith("## 13. Board profiles")


def test_a_section_that_is_none_is_one_line() -> None:
    done = run("protocol", "99")
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.startswith("appmode: error: no section '99' in the protocol reference")
    assert len(done.stderr.splitlines()) == 1


def _messages(path: Path) -> list[tuple[int, str]]:
    """The string constants of a module that are not docstrings: what a user may read."""
    tree = parsed(path.read_text(encoding="utf-8"))
    docstrings = {
        id(node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
    }
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docstrings
    ]


def test_no_message_or_help_sends_a_user_to_the_repository() -> None:
    cited = [
        f"{path.relative_to(ROOT)}:{line}"
        for path in ROOT.joinpath("appmode").rglob("*.py")
        for line, text in _messages(path)
        if ("docs/" in text or "README" in text) and " " in text  # a message, not a path
    ]
    assert not cited, f"messages that name a file of the repository: {cited}"
    assert "see appmode protocol 8)" in " ".join(run("board", "--help").stdout.split())
