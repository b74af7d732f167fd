"""Issue 49.12: on a real board, a transcript's preconditions hold whatever ran before it.

`conform --board` put the parameters back only at the end, so a transcript that relied
on a default failed after one that changed it (the tester's
`s13_set_value_from_the_last_digit` after the arithmetic transcript).
"""

from __future__ import annotations

from pathlib import Path

from appmode.protocol import params
from tests.support.processes import board_process, run

HEADER = "# appmode transcript v1\n@tolerance 0.3\n"


def test_each_transcript_finds_the_parameters_as_they_were(tmp_path: Path) -> None:
    default = params.DEFAULTS[2]
    changed = default + 7
    first = tmp_path / "a_changes.transcript"
    first.write_text(
        HEADER + f"0.1000 > {{2:{changed}}}\n0.4000 > {{Q:P}}\n"
        f"0.5000 < {{C*:*:{changed}:*:*:*:*:*:*}}$\n"
    )
    second = tmp_path / "b_relies_on_the_default.transcript"
    second.write_text(HEADER + f"0.1000 > {{Q:P}}\n0.2000 < {{C*:*:{default}:*:*:*:*:*:*}}$\n")
    with board_process("--pty", "-q") as board:
        done = run("conform", "--yes", "--board", board.url, str(first), str(second))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "2 passed, 0 failed" in done.stdout
