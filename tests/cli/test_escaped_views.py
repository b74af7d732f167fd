"""Issue 64.5: text from outside — a board's bytes, a profile file's texts, a suite's file
names — reaches no terminal as control characters, in every view: shown escaped, or
refused in one line that shows it escaped."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from tests.support.processes import run

HOSTILE = "\x1b]52;c;aGk=\x07\x1b[2K\r\x9b8m\u202e"
"""Writes the clipboard, erases the line, hides what follows, turns the text around."""
ACTED_ON = {"\x1b", "\x07", "\r", "\x9b", "\u202e"}


def clean(text: str) -> bool:
    return not set(text) & ACTED_ON


@pytest.mark.skipif(sys.platform == "win32", reason="a pseudo-terminal board")
@pytest.mark.parametrize("command", [("monitor", "--count", "3"), ("dump",)])
def test_a_board_s_text_is_shown_escaped(command: tuple[str, ...], tmp_path: Path) -> None:
    from tests.support.lenient_board import chatty_board

    record = tmp_path / "board.transcript"
    with chatty_board(HOSTILE.encode() + b" boot\r\n") as url:
        done = run("record", url, str(record), "--count", "3")
        assert done.returncode == 0, done.stderr
        if command[0] == "monitor":
            done = run("monitor", url, *command[1:])
    if command[0] == "dump":
        done = run("dump", str(record))
    assert done.returncode == 0, done.stderr
    assert clean(done.stdout + done.stderr), repr(done.stdout + done.stderr)
    assert "\\x1b]52;c;aGk=\\x07\\x1b[2K\\x0d" in done.stdout


def hostile_profile(tmp_path: Path) -> Path:
    path = tmp_path / "hostile.toml"
    label = HOSTILE.encode("unicode_escape").decode().replace("\\x", "\\u00")
    path.write_text(
        f'name = "hostile"\nlike = "sheet"\ndescription = "{label}"\n[pages]\nK = "{label}"\n',
        encoding="utf-8",
    )
    return path


@pytest.mark.parametrize(
    "command",
    [
        ("profile", "show", "{path}"),
        ("profile", "check", "{path}"),
        ("drive", "sim://", "--profile", "{path}"),
        ("monitor", "sim://?profile={path}", "--count", "1"),
        ("board", "--profile", "{path}", "--count", "1"),
    ],
    ids=lambda c: " ".join(c[:2]),
)
def test_a_profile_file_s_control_characters_are_refused_in_one_line(
    command: tuple[str, ...], tmp_path: Path
) -> None:
    path = hostile_profile(tmp_path)
    done = run(*(part.replace("{path}", str(path)) for part in command), timeout=20)
    assert done.returncode == 2, done.stderr
    assert clean(done.stdout + done.stderr), repr(done.stdout + done.stderr)
    assert "description = '\\x1b]52;c;aGk=\\x07" in done.stderr
    assert "Traceback" not in done.stderr


def test_conform_shows_a_suite_s_file_names_escaped(tmp_path: Path) -> None:
    folder = tmp_path / "suite"
    folder.mkdir()
    name = "ok\x1b]0;owned\x07\x1b[2K.transcript"
    (folder / name).write_text("# appmode transcript v1\n0.3000 < {A5:5:0:0}$\n")
    done = run("conform", str(folder))
    assert done.returncode == 1, done.stderr
    assert clean(done.stdout + done.stderr), repr(done.stdout)
    assert "FAIL" in done.stdout and "ok\\x1b]0;owned\\x07\\x1b[2K.transcript" in done.stdout


@pytest.mark.parametrize(
    "url", ["/dev/{long}", "zenoh://{long}", "socket://{long}:1", "sim://?{long}=1", "{long}"]
)
def test_a_10_kb_url_is_named_in_an_error_not_echoed(url: str) -> None:
    """Issue 64.12: an error repeated a 10 kB URL in full, twice."""
    done = run("params", url.replace("{long}", "a" * 10_000), timeout=20)
    assert done.returncode == 2
    assert len(done.stderr) < 600 and done.stderr.count("\n") == 1, done.stderr[:300]
    assert "(10," in done.stderr, "its length is said"
