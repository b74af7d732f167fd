"""The recorded example sessions in transcripts/examples: each says how it was recorded,
and each still passes against the embedded board (the board has not changed under it)."""

from __future__ import annotations

from pathlib import Path

import pytest

from appmode.transcript.reading import read_transcript
from tests.support.processes import ROOT, run

EXAMPLES = sorted((ROOT / "transcripts" / "examples").glob("*.transcript"))


def test_there_are_the_three_kinds_of_session() -> None:
    names = {p.stem for p in EXAMPLES}
    assert {"console_drive", "params_set_and_save", "uart2_session"} <= names


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_each_example_says_how_it_was_recorded(path: Path) -> None:
    transcript = read_transcript(path)
    assert "recorded with: " in transcript.title
    assert f"--record {path.name}" in transcript.title
    assert transcript.entries


def test_the_examples_pass_against_the_embedded_board() -> None:
    done = run("conform", "transcripts/examples")
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"{len(EXAMPLES)} passed, 0 failed" in done.stdout
