"""The command line: `appmode decode` (docs/design.md, "Contracts") and `appmode demo`."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.processes import ROOT, run


def appmode(*args: str, stdin: bytes = b"") -> subprocess.CompletedProcess[bytes]:
    return subprocess.run(
        [sys.executable, "-m", "appmode", *args],
        input=stdin,
        capture_output=True,
        timeout=60,
        check=False,
    )


def test_decode_example_from_the_issue() -> None:
    done = appmode("decode", stdin=b"{A1:2:3:0}$xx{B-5:0:90:87}$")
    assert done.returncode == 0, done.stderr
    objects = [json.loads(line) for line in done.stdout.decode().splitlines()]
    assert objects == [
        {"kind": "velocity", "x": 1, "y": 2, "z": 3, "extra": 0, "raw": "{A1:2:3:0}$"},
        {"kind": "garbage", "raw": "xx"},
        {
            "kind": "attitude",
            "pitch": -5,
            "roll": 0,
            "yaw": 90,
            "battery": 87,
            "raw": "{B-5:0:90:87}$",
        },
    ]


def test_decode_host_stream_groups_noise_runs(tmp_path: Path) -> None:
    capture = tmp_path / "host.bin"
    capture.write_bytes(b"JA\r\n\x00{0:800}{Q\x03P}{9:1}Z")
    done = appmode("decode", "--from", "host", str(capture))
    kinds = [json.loads(line)["kind"] for line in done.stdout.decode().splitlines()]
    assert kinds == ["page", "move", "noise", "set_param", "read_params", "bad_frame", "stop"]


def test_decode_missing_file_is_one_line_error() -> None:
    done = appmode("decode", "/nonexistent/capture.bin")
    assert done.returncode == 2
    assert done.stderr.decode().strip() == (
        "appmode: error: cannot read /nonexistent/capture.bin: No such file or directory"
    )


def test_demo_prints_the_route_and_records() -> None:
    done = appmode("demo", "--fast", "--drive", "diff")
    assert done.returncode == 0, done.stderr
    text = done.stdout.decode()
    assert text.startswith("SIMULATED board (diff drive)")
    assert "> {Q:P}" in text and "< {C500:10000:20:0:10:10:10:0:2}$" in text
    assert "< {C800:" in text, "the route's set is read back"
    assert "velocity x=0 y=500 z=0" in text, "forward at max speed on a differential drive"
    assert text.count("< {A") > 20 and text.count("< {B") > 20


def test_only_our_own_errors_become_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 22.14: a ValueError from a bug is not dressed up as a user's mistake: it is
    named a bug (exit 70, where in appmode it happened); a value out of range
    (InvalidValue, a ValueError too) is one line, as before."""
    from appmode.cli import main as cli_main
    from appmode.cli import ports
    from appmode.errors import InvalidValue

    def buggy(args: object) -> int:
        raise ValueError("a bug\nin two lines")

    monkeypatch.setattr(ports, "run", buggy)
    monkeypatch.delenv("APPMODE_TRACEBACK", raising=False)
    assert cli_main.main(["ports"]) == 70
    err = capsys.readouterr().err
    line = err.rstrip("\n")
    assert "\n" not in line, "one line"
    assert line.startswith("appmode: internal error: ValueError: a bug in two lines at ")
    assert "tests/cli/test_cli_core.py:" in line and "a bug in appmode" in line
    assert "APPMODE_TRACEBACK=1" in line and "Traceback" not in line

    monkeypatch.setenv("APPMODE_TRACEBACK", "1")
    assert cli_main.main(["ports"]) == 70
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last):")
    assert "ValueError: a bug" in err and "in buggy" in err

    def refused(args: object) -> int:
        raise InvalidValue("max_speed (parameter 0) must be in 0–65535, not 70000")

    monkeypatch.setattr(ports, "run", refused)
    assert cli_main.main(["ports"]) == 2
    assert capsys.readouterr().err == (
        "appmode: error: max_speed (parameter 0) must be in 0–65535, not 70000\n"
    )


def test_a_bug_in_a_served_board_ends_it_in_one_line() -> None:
    """A board whose model fails (here made to, in a subprocess) says so in a line and
    exits 70, not with a traceback."""
    code = (
        "import sys\n"
        "from appmode.board import vehicle\n"
        "def broken(self, *args, **kwargs):\n"
        "    raise ZeroDivisionError('division by zero')\n"
        "vehicle.Vehicle.step = broken\n"
        "from appmode.cli.main import main\n"
        "sys.exit(main(['board', '--pty', '--quiet']))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, timeout=60, check=False
    )
    assert done.returncode == 70, done.stderr
    err = done.stderr.decode()
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("appmode: internal error: ZeroDivisionError: division by zero at ")
    assert "a bug in appmode" in err


def test_the_errors_the_docs_name_are_importable_from_appmode() -> None:
    import appmode

    assert issubclass(appmode.TranscriptError, appmode.AppmodeError)
    assert {"AppmodeError", "TranscriptError"} <= set(appmode.__all__)


def test_the_command_line_loads_a_commands_machinery_only_to_run_it() -> None:
    """Issue 28.2: `appmode --help` imported every command's host, board and probe."""
    heavy = (
        "appmode.host.app.client",
        "appmode.host.probe",
        "appmode.cli.hostio",
        "appmode.cli.uart2",
        "appmode.board.firmware",
        "appmode.ports.sim",
        "appmode.console.driving",
    )
    loaded = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from appmode.cli.main import build_parser; build_parser(); "
            f"print([m for m in {heavy!r} if m in sys.modules])",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert loaded.stdout.strip() == "[]"
    commands = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from appmode.cli.main import build_parser; "
            "from appmode.cli.commands import COMMANDS; "
            "build_parser(sys.argv[1]).parse_args(sys.argv[2:]); "
            "print(sorted(m for m in COMMANDS if 'appmode.cli.' + m in sys.modules))",
            "send",
            "send",
            "sim://",
            "Z",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert commands.stdout.strip() == "['send']", "only the command that runs is loaded"


def test_appmode_alone_lists_the_commands_and_a_typo_gets_the_nearest() -> None:
    """Issue 52.3: plain `appmode` said only 'the following arguments are required'."""
    alone = run()
    assert alone.returncode == 0
    assert re.search(r"\n +drive +drive and tune a car", alone.stdout), alone.stdout
    typo = run("drvie")
    assert typo.returncode == 2
    assert typo.stderr == (
        "appmode: error: unknown command 'drvie': did you mean 'drive'? (appmode --help "
        "lists the commands)\n"
    )
    assert run("xyzzy").stderr.endswith(
        "unknown command 'xyzzy' (appmode --help lists the commands)\n"
    )


def test_version_names_the_commit_in_a_checkout() -> None:
    """Issue 52.4: `appmode --version` run from a checkout also names its commit."""
    head = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT
    )
    done = run("--version")
    assert done.returncode == 0 and done.stdout.startswith("appmode 0.1.0")
    if head.returncode == 0:  # a checkout (an sdist has no .git)
        assert head.stdout.strip() in done.stdout


def test_every_command_s_help_ends_with_examples_that_parse() -> None:
    """Issue 52.3: no help text had an example."""
    import shlex

    from appmode.cli.commands import COMMANDS, EXAMPLES
    from appmode.cli.main import build_parser

    assert set(EXAMPLES) == set(COMMANDS)
    for name, examples in EXAMPLES.items():
        assert 1 <= len(examples) <= 3, name
        parser = build_parser(name)
        words = shlex.split(examples[0])
        assert words[:2] == ["appmode", name]
        for example in examples:
            words = shlex.split(example)
            words = words[words.index("appmode") + 1 :]
            for stop in ("<", ">", "|"):
                words = words[: words.index(stop)] if stop in words else words
            assert words[0] == name, example
            parser.parse_args(words)  # SystemExit (a usage error) fails the test
        help_text = run(name, "--help").stdout
        assert help_text.rstrip().endswith(f"$ {examples[-1]}"), name
