"""Output that cannot be written ends with one clear line, never a traceback: a reader
that left (`| head -1`) ends the command quietly, a full disk or a closed stdout is an
error; a closed stdin reads as empty."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from tests.support.processes import ROOT, appmode_cmd

STREAM = b"{A0:500:0:0}$" * 50_000  # 650 KB: more than a pipe holds


@pytest.fixture
def capture(tmp_path: Path) -> Path:
    path = tmp_path / "capture.bin"
    path.write_bytes(STREAM)
    return path


def test_a_reader_that_leaves_ends_decode_quietly(capture: Path) -> None:
    proc = subprocess.Popen(
        appmode_cmd("decode", str(capture)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=ROOT,
    )
    assert proc.stdout is not None and proc.stderr is not None
    assert proc.stdout.readline().startswith(b'{"kind": "velocity"')
    proc.stdout.close()  # as `head -1` does
    assert proc.wait(30) == 0
    assert proc.stderr.read() == b""


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("from_stdin", [False, True])
def test_a_full_disk_is_one_clear_error(capture: Path, from_stdin: bool) -> None:
    with open("/dev/full", "wb") as full, capture.open("rb") as data:
        args = ("decode",) if from_stdin else ("decode", str(capture))
        done = subprocess.run(
            appmode_cmd(*args), stdin=data, stdout=full, stderr=subprocess.PIPE, cwd=ROOT
        )
    assert done.returncode == 2
    assert done.stderr.decode() == (
        "appmode: error: cannot write the output: No space left on device\n"
    )


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("args", [("--help",), ("send", "--help"), ("--version",)])
def test_help_to_a_full_disk_is_one_clear_error(args: tuple[str, ...]) -> None:
    """It ended with status 0 and said nothing: the help was lost unnoticed."""
    with open("/dev/full", "wb") as full:
        done = subprocess.run(appmode_cmd(*args), stdout=full, stderr=subprocess.PIPE, cwd=ROOT)
    assert done.returncode == 2
    assert done.stderr.decode() == (
        "appmode: error: cannot write the output: No space left on device\n"
    )


def test_closed_stdout_and_stdin(capture: Path) -> None:
    closed_out = subprocess.run(
        ["sh", "-c", 'exec "$@" >&-', "sh", *appmode_cmd("decode", str(capture))],
        stderr=subprocess.PIPE,
        cwd=ROOT,
    )
    assert closed_out.returncode == 2
    assert closed_out.stderr.decode().startswith("appmode: error: standard output is closed")
    closed_in = subprocess.run(
        ["sh", "-c", 'exec "$@" <&-', "sh", *appmode_cmd("decode")],
        capture_output=True,
        cwd=ROOT,
    )
    assert (closed_in.returncode, closed_in.stdout, closed_in.stderr) == (0, b"", b"")
