"""Issue 52.4: shell completion for bash, zsh and fish (argcomplete), one command to
install it, and the answers the shell gets when it asks."""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.processes import run, wait_for


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


def test_profiles_complete_by_name_and_as_files(tmp_path: Path) -> None:
    """Issue 69.4: `--profile <Tab>` and `profile show <Tab>` listed files only."""
    (tmp_path / "mycar.toml").write_text('name = "mycar"\n')
    (tmp_path / "notes.txt").write_text("")
    for line in ("appmode drive --profile ", "appmode profile show ", "appmode dump x --profile "):
        assert {"sheet", "minibalance", "balance"} <= set(ask(line, tmp_path)), line
        offered = ask(f"{line}{tmp_path}/", tmp_path)
        assert f"{tmp_path}/mycar.toml" in offered and f"{tmp_path}/notes.txt" not in offered
    assert ask("appmode profile show mi", tmp_path) == ["minibalance"]


def test_plain_bash_completes_with_the_eval_line(tmp_path: Path) -> None:
    """Issue 69.4: in bash without the bash-completion package the completions folder is
    never read; the eval line the guide gives works in any bash. Typed in tmux."""
    if shutil.which("tmux") is None:
        pytest.fail("tmux is needed to type in a real bash (apt-get install tmux)")
    rc = tmp_path / "bashrc"
    rc.write_text(
        f"export PATH={shlex.quote(str(Path(sys.executable).parent))}:$PATH\n"
        'eval "$(appmode completion bash)"\nPS1="ready$ "\n'
    )
    server = ["tmux", "-L", f"appmode-completion-{os.getpid()}"]
    bash = f"env -i HOME={tmp_path} TERM=xterm bash --noprofile --rcfile {rc} -i"
    subprocess.run([*server, "new-session", "-d", "-s", "c", "-x", "120", "-y", "20", bash],
                   check=True)  # fmt: skip

    def screen() -> str:
        done = subprocess.run([*server, "capture-pane", "-t", "c", "-p"], capture_output=True,
                              text=True, check=False)  # fmt: skip
        return done.stdout

    try:
        wait_for(lambda: "ready$" in screen(), 10)
        subprocess.run([*server, "send-keys", "-t", "c", "appmode profile show mi", "Tab"],
                       check=True)  # fmt: skip
        wait_for(lambda: "appmode profile show minibalance" in screen(), 10)
    finally:
        subprocess.run([*server, "kill-server"], capture_output=True, check=False)
