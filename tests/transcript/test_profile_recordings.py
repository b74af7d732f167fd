"""Issue 64.8: recordings made with a profile file name it (its name and the digest of
its text) and read back with `--profile FILE`: dump, plot and conform; a file may not
take a shipped profile's name (it would be recorded as that firmware)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from tests.support.processes import board_process, run

MINE = """name = "mybal"
description = "my balance car"
source = "its show.c"
like = "balance"
"""


@pytest.fixture
def mine(tmp_path: Path) -> Path:
    path = tmp_path / "mybal.toml"
    path.write_text(MINE)
    return path


def board_line(path: Path) -> str:
    return next(line for line in path.read_text().splitlines() if line.startswith("@board"))


def test_a_recording_names_the_file_s_profile_and_digest(mine: Path, tmp_path: Path) -> None:
    digest = hashlib.sha256(MINE.encode()).hexdigest()[:16]
    drove = tmp_path / "drive.transcript"
    done = run("send", f"sim://?profile={mine}", "J", "--record", str(drove))
    assert done.returncode == 0, done.stderr
    assert board_line(drove) == f"@board profile=mybal digest={digest}"
    served = tmp_path / "board.transcript"
    with board_process("--pty", "--profile", str(mine), "--record", str(served)):
        pass
    assert board_line(served) == f"@board profile=mybal digest={digest}"


@pytest.mark.parametrize("command", ["dump", "plot", "conform", "convert"])
def test_it_reads_back_with_the_file_and_says_what_to_give_without_it(
    command: str, mine: Path, tmp_path: Path
) -> None:
    drove = tmp_path / "drive.transcript"
    assert run("send", f"sim://?profile={mine}", "J", "--record", str(drove)).returncode == 0
    outputs = {"plot": ["-o", str(tmp_path / "p.png")], "convert": [str(tmp_path / "d.mcap")]}
    extra = outputs.get(command, [])
    without = run(command, str(drove), *extra)
    assert without.returncode != 0
    assert "profile=mybal is a profile file's (digest " in without.stderr
    assert "give that file with --profile FILE" in without.stderr
    with_it = run(command, str(drove), *extra, "--profile", str(mine))
    assert with_it.returncode == 0, with_it.stderr
    if command == "dump":
        assert "{A" in with_it.stdout
    changed = tmp_path / "changed" / "mybal.toml"
    changed.parent.mkdir()
    changed.write_text(MINE.replace("my balance car", "my other car"))
    other = run(command, str(drove), *extra, "--profile", str(changed))
    assert other.returncode != 0 and "give the file it was recorded with" in other.stderr


def test_a_file_may_not_take_a_shipped_profile_s_name(tmp_path: Path) -> None:
    sheet = tmp_path / "sheet.toml"
    sheet.write_text('name = "sheet"\nlike = "balance"\n')
    done = run("profile", "check", str(sheet))
    assert done.returncode == 2
    assert "name = 'sheet': a shipped profile's name" in done.stderr
