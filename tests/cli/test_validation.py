"""Values that cannot finish or make no sense are refused with one line naming the range
(nothing hangs on inf, nan or a speed of 1e-308), numbers are ASCII digits, and
transcript lines are numbered as an editor numbers them."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from appmode.protocol.transcript import parse_transcript
from tests.support.processes import ROOT, run

MINIBALANCE = ROOT / "transcripts" / "suite" / "minibalance"
LAST_DIGIT = "s13_set_value_from_the_last_digit.transcript"
"""A set only the reference firmware reads back so (123456789 as 123456784), ±0.3 s: the
power-up's ±10 ms, in real time, was missed on a busy machine."""
REFUSED = [
    ("send", "sim://", "Z", "--listen", "inf"),
    ("send", "sim://", "Z", "--listen", "nan"),
    ("send", "sim://", "Z", "--listen", "-1"),
    ("monitor", "sim://", "--count", "0"),
    ("monitor", "sim://", "--duration", "nan"),
    ("replay", "x.transcript", "--to", "sim://", "--speed", "1e-308"),
    ("replay", "x.transcript", "--to", "sim://", "--speed", "nan"),
    ("drive", "--hold-first", "0"),
    ("board", "--count", "10000"),
    ("params", "sim://", "--set", "max_speed=٨٠٠"),
    ("params", "sim://", "--set", "max_speed=" + "9" * 5000),
    ("params", "sim://?baud=1"),
    ("params", "socket://localhost"),
    ("params", "rfc2217://localhost:99999"),
]


@pytest.mark.parametrize("args", REFUSED, ids=[" ".join(a)[:40] for a in REFUSED])
def test_refused_with_one_line(args: tuple[str, ...]) -> None:
    done = run(*args, timeout=20)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert "error:" in last and ("in [" in last or "in (" in last or "–" in last), last


@pytest.mark.parametrize(
    "line, message",
    [("1e308 > Z", "0–86400"), ("inf > Z", "0–86400"), ("１ > Z", "not seconds")],
)
def test_transcript_times_that_could_not_finish_are_refused(
    tmp_path: Path, line: str, message: str
) -> None:
    path = tmp_path / "t.transcript"
    path.write_text(f"# appmode transcript v1\n0.0 > J\n{line}\n")
    done = run("conform", str(path), timeout=20)
    assert done.returncode == 2 and f"{path}:3: " in done.stderr and message in done.stderr


def test_tolerance_inf_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "t.transcript"
    path.write_text("# appmode transcript v1\n@tolerance inf\n0.0 > Z\n")
    done = run("conform", str(path), timeout=20)
    assert done.returncode == 2 and f"{path}:2: @tolerance" in done.stderr


def test_a_bom_and_odd_line_breaks_in_comments_keep_line_numbers() -> None:
    text = "\ufeff# appmode transcript v1\n# a \x0c form feed and a \u2028 separator\n0.5 > Z\n"
    transcript = parse_transcript(text)
    assert [(e.lineno, e.data) for e in transcript.entries] == [(3, b"Z")]


def test_a_bad_url_leaves_an_existing_recording_untouched(tmp_path: Path) -> None:
    record = tmp_path / "precious.transcript"
    record.write_text("precious\n")
    done = run("send", "/dev/no-such-port", "Z", "--record", str(record), timeout=20)
    assert done.returncode == 2 and "no such port" in done.stderr
    assert record.read_text() == "precious\n"


def test_a_transcript_with_nothing_to_check_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "empty.transcript"
    path.write_text("# appmode transcript v1\n# only a comment\n")
    done = run("conform", str(path), timeout=20)
    assert done.returncode == 2 and "PASS" not in done.stdout
    assert done.stderr == f"appmode: error: {path} has no '>' or '<' lines: nothing to check\n"


def test_odd_inputs_end_in_one_line_naming_what_and_where(tmp_path: Path) -> None:
    """Issue 22.10: each of these was a traceback or a message that said nothing."""
    digits = tmp_path / "digits.transcript"
    digits.write_text("# appmode transcript v1\n0.0 > J\n0.5 < {A" + "9" * 5000 + ":0:0:0}$\n")
    cases = [
        (("conform", str(digits)), f"{digits}:3: a field of 5,000 digits"),
        (("dump", str(digits)), f"{digits}:3: a field of 5,000 digits"),
        (("params", "socket://[::1"), "needs a host and a port 1–65535"),
        (("params", "/dev/tty"), "/dev/tty is not a device this program can open"),
    ]
    for args, message in cases:
        done = run(*args, timeout=20)
        assert done.returncode == 2, (args, done.stderr)
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and message in lines[0], (args, done.stderr)
        assert lines[0].count("Errno") <= 1, "the reason is said once"


def test_a_fifo_nobody_reads_is_waited_on_saying_so(tmp_path: Path) -> None:
    """Issue 22.10: a FIFO with no reader for --record hung in silence; issue 49.1: it
    then held up the session. Now the wait is said, the command runs to its end, and
    the recording nobody read is one line and a non-zero exit."""
    fifo = tmp_path / "out"
    os.mkfifo(fifo)
    for args in (
        ("record", "sim://", str(fifo), "--count", "2"),
        ("send", "sim://", "J", "--record", str(fifo)),
    ):
        done = run(*args, timeout=20)
        lines = done.stderr.splitlines()
        waiting = f"appmode: waiting for a program to read the FIFO {fifo}"
        assert any(line.startswith(waiting) for line in lines), done.stderr
        assert lines[-1] == (
            f"appmode: error: cannot write transcript {fifo}: no program opened it to read "
            "within 0.5 s of the end"
        ), done.stderr
        assert done.returncode == 2 and "Traceback" not in done.stderr


def _default_sigint() -> None:
    """A child with Ctrl-C as a terminal gives it (a test run in the background, `pytest
    &`, has SIGINT ignored, and Python then keeps it ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_started_as_the_program_a_ctrl_c_ends_it_quietly_from_the_first_import(
    tmp_path: Path,
) -> None:
    """Issue 22.10: SIGINT while appmode loads gave a KeyboardInterrupt traceback. Started
    as `appmode`, the quiet handler is in place before pyserial loads; a program that
    imports appmode keeps its own."""
    probe = "import appmode, signal; print(getattr(signal.getsignal(signal.SIGINT), '__name__'))"
    script = tmp_path / "appmode"
    script.write_text(probe + "\n")
    default = {"preexec_fn": _default_sigint} if os.name == "posix" else {}
    as_program = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, cwd=ROOT, **default
    )
    assert (as_program.returncode, as_program.stdout.strip()) == (0, "_quit"), as_program.stderr
    imported = subprocess.run(  # started as a terminal starts it, whoever runs the tests
        [sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, **default
    )
    assert (imported.returncode, imported.stdout.strip()) == (0, "default_int_handler"), (
        imported.stderr
    )


@pytest.mark.parametrize(
    "args, shown",
    [
        (("params", "sim://", "--json"), '"max_speed": 30,'),
        (("send", "sim://", "{Q:P}", "wait:1.5"), "< {C30:3000:40:"),
        (("monitor", "sim://", "--filter", "A", "--count", "1"), "battery=-740%"),
        (("drive", "sim://"), "max_speed 30 · max_position 3000"),
        (
            ("conform", "--board", "sim://", str(MINIBALANCE / LAST_DIGIT)),
            "1 passed, 0 failed against sim://?profile=minibalance",
        ),
    ],
    ids=["params", "send", "monitor", "drive", "conform"],
)
def test_a_profile_given_with_a_sim_url_is_the_simulated_boards(
    args: tuple[str, ...], shown: str
) -> None:
    """`--profile minibalance` on sim:// serves the reference firmware's board (its own
    parameters; its battery reads −740 % for 1.9 s, §13), not the sheet's board decoded
    as if it were that one."""
    done = run(*args, "--profile", "minibalance", timeout=30, stdin=b"params\nstatus\n")
    assert done.returncode == 0, done.stderr
    assert shown in done.stdout, done.stdout


@pytest.mark.parametrize(
    "args, url, name, value",
    [
        (("params", "URL"), "sim://?profile=sheet", "profile", "minibalance"),
        (("send", "URL", "A"), "sim://?profile=minibalance", "profile", "sheet"),
        (("monitor", "URL", "--count", "1"), "sim://?profile=sheet", "profile", "minibalance"),
        (("drive", "URL"), "sim://?drive=omni", "drive", "mecanum"),
        (("conform", "--board", "URL"), "sim://?profile=sheet", "profile", "minibalance"),
    ],
    ids=["params", "send", "monitor", "drive", "conform"],
)
def test_a_profile_or_drive_that_the_sim_url_contradicts_is_refused(
    args: tuple[str, ...], url: str, name: str, value: str
) -> None:
    command = [url if arg == "URL" else arg for arg in args]
    done = run(*command, f"--{name}", value, timeout=20)
    assert done.returncode == 2
    assert done.stderr == (
        f"appmode: error: {url} sets {url.split('?')[1]}, and --{name} {value} another: give "
        f"the {name} once\n"
    )
