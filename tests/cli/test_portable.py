"""appmode on a system without POSIX modules (Windows): `import appmode` and the host
commands work with fcntl, termios, pty and tty unimportable; what needs a pty says so."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.support.processes import ROOT

WITHOUT_POSIX = """
import sys
import serial  # pyserial picks its own back end per system first: not ours to judge
for name in ("fcntl", "termios", "pty", "tty", "resource", "grp", "pwd"):
    sys.modules[name] = None  # `import fcntl` now fails, as on Windows
import appmode
from appmode.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


def appmode_without_posix(*args: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", WITHOUT_POSIX, *args],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
        check=False,
    )


@pytest.mark.parametrize(
    "args",
    [
        ("--help",),
        ("send", "sim://", "J", "A", "wait:0.2"),
        ("send", "sim://", "--uart2", "velocity:0,100,0", "wait:0.1"),
        ("params", "sim://"),
        ("monitor", "sim://", "--count", "2"),
        ("conform",),
        ("dump", "transcripts/examples/console_drive.transcript"),
        ("replay", "transcripts/examples/params_set_and_save.transcript", "--to", "sim://"),
    ],
    ids=lambda a: " ".join(a),
)
def test_host_commands_run_without_posix_modules(args: tuple[str, ...]) -> None:
    done = appmode_without_posix(*args)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr


def test_the_console_runs_a_script_without_posix_modules() -> None:
    done = appmode_without_posix("drive", stdin="drive A\nwait 0.3\nstop\nquit\n")
    assert done.returncode == 0, done.stderr
    assert "parameters read" in done.stdout


@pytest.mark.parametrize(
    ("args", "hint"),
    [
        (
            ("board", "--listen", "127.0.0.1:0"),
            "serve on TCP with --listen HOST:PORT and --listen2",
        ),
        (
            (
                "replay",
                "transcripts/examples/console_drive.transcript",
                "--to",
                "pty",
                "--side",
                "board",
            ),
            "instead of pty",
        ),
    ],
    ids=["board", "replay"],
)
def test_what_needs_a_pty_says_so_in_one_line(args: tuple[str, ...], hint: str) -> None:
    done = appmode_without_posix(*args)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "no pseudo-terminals" in lines[0] and hint in lines[0]
