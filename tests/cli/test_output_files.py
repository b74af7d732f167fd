"""The files commands write: a FIFO gets its report in place, a missing folder is named
before any work is done, a recording is only created once the port opened, and a
recording that can no longer be written ends the command with one line."""

from __future__ import annotations

import os
import resource
import stat
import subprocess
from pathlib import Path

import pytest

from tests.support.processes import ROOT, appmode_cmd, run
from tests.test_files import fifo_reader


def _one_error_line(done: subprocess.CompletedProcess[str], text: str) -> None:
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr, done.stderr
    assert text in done.stderr, done.stderr


def test_a_junit_report_into_a_fifo_is_written_in_place(tmp_path: Path) -> None:
    fifo = tmp_path / "report"
    with fifo_reader(fifo) as got:
        done = run("conform", "--junit", str(fifo), timeout=60)
    assert done.returncode == 0, done.stderr
    assert got[0].startswith(b"<?xml") and b'failures="0"' in got[0]
    assert stat.S_ISFIFO(fifo.lstat().st_mode)


@pytest.mark.parametrize(
    "args, what",
    [
        (("conform", "--junit", "{missing}/report.xml"), "JUnit report"),
        (("plot", "{transcript}", "-o", "{missing}/plot.png"), "plot"),
    ],
)
def test_a_missing_folder_is_named_before_any_work(
    tmp_path: Path, args: tuple[str, ...], what: str
) -> None:
    transcript = tmp_path / "t.transcript"
    transcript.write_text("# appmode transcript v1\n0.0 > Z\n")
    missing = tmp_path / "missing"
    done = run(*(a.format(missing=missing, transcript=transcript) for a in args), timeout=60)
    _one_error_line(done, f"cannot write {what} {missing}/")
    assert "there is no folder" in done.stderr and "PASS" not in done.stdout


@pytest.mark.parametrize(
    "args",
    [
        ("board", "--port", "/dev/no-such-port"),
        ("drive", "/dev/no-such-port"),
        ("tap", "pty", "/dev/no-such-port"),
    ],
)
def test_a_port_that_does_not_open_leaves_an_existing_recording(
    tmp_path: Path, args: tuple[str, ...]
) -> None:
    record = tmp_path / "precious.transcript"
    record.write_text("precious\n")
    done = run(*args, "--record", str(record), timeout=20, stdin=b"quit\n")
    _one_error_line(done, "no such port")
    assert record.read_text() == "precious\n"


def test_a_recording_whose_reader_leaves_ends_the_board_with_one_line(tmp_path: Path) -> None:
    fifo = tmp_path / "live.transcript"
    os.mkfifo(fifo)
    proc = subprocess.Popen(
        appmode_cmd("board", "--quiet", "--record", str(fifo)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    with fifo.open("rb") as reader:  # the board opens the FIFO once its pty is up
        assert reader.readline() == b"# appmode transcript v1\n"
    assert proc.stdout is not None
    url = proc.stdout.readline().split("port: ")[1].strip()
    import termios

    import serial

    try:  # the board records what it sends and receives, and finds nobody reading
        with serial.serial_for_url(url, baudrate=9600, timeout=0.1) as port:
            for _ in range(50):
                port.write(b"A")
                port.read(64)
    except (serial.SerialException, OSError, termios.error):
        pass  # the board has gone (its first record found the reader gone): its pty too,
        # perhaps while pyserial was opening it (termios.error is no OSError)
    _, err = proc.communicate(timeout=20)
    assert proc.returncode == 2
    assert err == f"appmode: error: cannot write transcript {fifo}: its reader left\n"


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("command", [("send", "sim://", "A"), ("board",), ("drive",)])
def test_a_recording_on_a_full_disk_is_one_line(command: tuple[str, ...]) -> None:
    done = run(*command, "--record", "/dev/full", timeout=20, stdin=b"quit\n")
    _one_error_line(done, "cannot write transcript /dev/full: No space left on device")


def test_running_out_of_ptys_is_one_line() -> None:
    def few_files() -> None:
        resource.setrlimit(resource.RLIMIT_NOFILE, (64, 64))

    done = subprocess.run(
        appmode_cmd("board", "--count", "100", "--quiet"),
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
        preexec_fn=few_files,
    )
    assert done.returncode == 2
    assert done.stderr.startswith("appmode: error: cannot open another pseudo-terminal")
    assert done.stderr.count("\n") == 1 and "--count" in done.stderr
    assert "may open no more files" in done.stderr and "ulimit -n" in done.stderr  # 22.10


@pytest.mark.parametrize(
    "args",
    [
        ("record", "sim://", "", "--count", "3"),
        ("send", "sim://", "J", "--record", ""),
        ("drive", "--record", " "),
        ("board", "--flash", ""),
        ("conform", "--junit", ""),
        ("tap", "pty", "sim://", "--record", ""),
        ("dump", ""),
        ("plot", "x.transcript", "-o", ""),
    ],
    ids=lambda a: " ".join(a[:2]),
)
def test_an_empty_file_name_is_refused_not_taken_for_none(args: tuple[str, ...]) -> None:
    """Issue 22.11: `record sim:// ''` used to say it recorded and write nothing."""
    done = run(*args, timeout=20)
    assert done.returncode == 2
    assert "an empty file name: name a file" in done.stderr
    assert "Traceback" not in done.stderr
