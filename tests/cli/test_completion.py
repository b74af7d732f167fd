"""Issue 52.4: shell completion for bash, zsh and fish (argcomplete), one command to
install it, and the answers the shell gets when it asks."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from tests.support.processes import run


def ask(line: str, tmp_path: Path) -> list[str]:
    """What appmode answers when a shell asks it to complete `line` (as the scripts ask)."""
    answer = tmp_path / "answer"
    done = run(
        env={
            "_ARGCOMPLETE": "1",
            "_ARGCOMPLETE_IFS": "\v",
            "COMP_LINE": line,
            "COMP_POINT": str(len(line)),
            "_ARGCOMPLETE_STDOUT_FILENAME": str(answer),
        }
    )
    assert done.returncode == 0, done.stderr
    return sorted(word.strip() for word in answer.read_text().split("\v") if word.strip())


def test_commands_options_and_choices_complete(tmp_path: Path) -> None:
    assert ask("appmode d", tmp_path) == ["decode", "demo", "doctor", "drive", "dump"]
    assert "--drive" in ask("appmode board --dr", tmp_path)
    assert ask("appmode board --drive ", tmp_path) == ["diff", "diff-gyro", "mecanum", "omni"]
    assert [w for w in ask("appmode completion ", tmp_path) if w[0] != "-"] == [
        "bash",
        "fish",
        "zsh",
    ]


@pytest.mark.parametrize("shell", ["bash", "zsh", "fish"])
def test_each_shell_gets_a_script_that_asks_appmode(shell: str) -> None:
    done = run("completion", shell)
    assert done.returncode == 0, done.stderr
    assert "_ARGCOMPLETE" in done.stdout and "appmode" in done.stdout


def test_bash_registers_the_script() -> None:
    if shutil.which("bash") is None:
        pytest.fail("bash is needed to check the bash script")
    script = run("completion", "bash").stdout
    done = subprocess.run(
        ["bash", "-c", script + "\ncomplete -p appmode"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0 and "_python_argcomplete appmode" in done.stdout, done.stderr


def test_a_shell_it_does_not_know_is_one_line() -> None:
    done = run("completion", "tcsh")
    assert done.returncode == 2 and "invalid choice: 'tcsh'" in done.stderr
    assert len(done.stderr.strip().splitlines()) <= 2
