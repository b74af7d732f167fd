"""Issue 49.1, 49.3 and 49.10: no recording, output or terminal holds up the stop or a
signal, judged on the board's own recording.

Before the bounded writers, a recording to a FIFO nobody reads froze the session (the
car drove on, and signals were ignored), `send`'s final `Z` waited for its stdout, and a
recording lost on a full disk ended `drive` with status 0.
"""

from __future__ import annotations

import fcntl
import os
import resource
import signal
import subprocess
import time
from pathlib import Path

import pytest

from tests.support.processes import ROOT, appmode_cmd, board_process, run, stop_process

F_SETPIPE_SZ = 1031  # Linux: a pipe's capacity


def received(record: Path) -> list[tuple[float, str]]:
    """(board time, payload) of what the board received on its APP port."""
    lines = [line.split(" ", 2) for line in record.read_text().splitlines() if " > " in line]
    return [(float(t), payload) for t, _, payload in lines]


def a_to_z(record: Path) -> float:
    """Board seconds from the first `A` to the first `Z` after it."""
    got = received(record)
    start = next(i for i, (_, payload) in enumerate(got) if payload == "A")
    return next(t for t, payload in got[start:] if payload == "Z") - got[start][0]


@pytest.mark.timing  # a drive of 0.9 s at least, from A to Z: 0.86 s when starved
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_recording_to_a_fifo_nobody_reads_never_holds_the_car(tmp_path: Path) -> None:
    fifo, board_record = tmp_path / "rec", tmp_path / "board.transcript"
    os.mkfifo(fifo)
    with board_process("--pty", "--quiet", "--record", str(board_record)) as board:
        started = time.monotonic()
        done = run(
            "drive", board.url, "--record", str(fifo), stdin=b"drive A\nwait 1\nquit\n", timeout=30
        )
        took = time.monotonic() - started
    assert 0.9 <= a_to_z(board_record) < 1.6
    assert took < 10, took
    assert done.returncode == 1, done.stderr
    assert f"error: cannot write transcript {fifo}: " in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
@pytest.mark.timing
def test_signals_end_a_session_recording_to_a_fifo_nobody_reads(tmp_path: Path) -> None:
    """The tester's SIGINT, SIGTERM and SIGHUP did nothing: the session was stuck in a
    write to the FIFO, inside a step no signal may cut."""
    fifo, board_record = tmp_path / "rec", tmp_path / "board.transcript"
    os.mkfifo(fifo)
    with board_process("--pty", "--quiet", "--record", str(board_record)) as board:
        proc = subprocess.Popen(
            appmode_cmd("drive", board.url, "--record", str(fifo)),
            stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            cwd=ROOT,
            text=True,
        )
        assert proc.stdin is not None
        proc.stdin.write("drive A\n")
        proc.stdin.flush()
        deadline = time.monotonic() + 10
        while not any(p == "A" for _, p in received(board_record)):
            assert time.monotonic() < deadline, "the board never got A"
            time.sleep(0.05)
        signalled = time.monotonic()
        err = stop_process(proc, signal.SIGTERM)
        ended = time.monotonic() - signalled
    assert ended < 1.5, (ended, err)
    assert received(board_record)[-1][1] == "Z"


@pytest.mark.timing
def test_send_s_stop_never_waits_for_its_output(tmp_path: Path) -> None:
    """`send P J A wait:3` into a 4 KiB pipe nobody reads: the car drove on past the
    wait (the tester's `Z` came only with SIGINT)."""
    board_record = tmp_path / "board.transcript"
    read_end, write_end = os.pipe()
    fcntl.fcntl(write_end, F_SETPIPE_SZ, 4096)
    try:
        with board_process("--pty", "--quiet", "--record", str(board_record)) as board:
            proc = subprocess.Popen(
                appmode_cmd("send", board.url, "--json", "J", "A", "wait:3"),
                stdout=write_end,
                stderr=subprocess.PIPE,
                cwd=ROOT,
                text=True,
            )
            deadline = time.monotonic() + 20
            while not any(p == "Z" for _, p in received(board_record)):
                assert time.monotonic() < deadline, received(board_record)[-5:]
                time.sleep(0.1)
            assert 2.9 <= a_to_z(board_record) < 3.8
            assert proc.poll() is None  # what it printed is still unread: it waits to write
            signalled = time.monotonic()
            stop_process(proc, signal.SIGINT)
            assert time.monotonic() - signalled < 1.5
    finally:
        os.close(read_end)
        os.close(write_end)


def _small_files() -> None:
    resource.setrlimit(resource.RLIMIT_FSIZE, (1024, 1024))


def test_a_recording_lost_to_a_file_size_limit_is_an_error(tmp_path: Path) -> None:
    """Issue 49.10: `ulimit -f 2` lost the recording with a line on stdout, exit 0."""
    record = tmp_path / "drive.transcript"
    done = run(
        "drive",
        "--record",
        str(record),
        stdin=b"drive A\nwait 3\nquit\n",
        limits=_small_files,
    )
    assert done.returncode == 1, done.stdout
    assert f"appmode: error: cannot write transcript {record}: " in done.stderr
    assert "recording stopped" in done.stderr
    assert "recording stopped" not in done.stdout


def test_decode_is_bounded_on_a_stream_of_zeros(tmp_path: Path) -> None:
    """Issue 49.9: 100 MB of zeros grew decode to 1.7 GB (one 500 MB JSON line)."""
    zeros = tmp_path / "zeros"
    with zeros.open("wb") as f:
        f.truncate(20_000_000)
    out = tmp_path / "out.jsonl"
    with out.open("w") as sink:
        proc = subprocess.Popen(
            [*appmode_cmd("decode", str(zeros))], stdout=sink, stderr=subprocess.PIPE, cwd=ROOT
        )
        _, usage = os.wait4(proc.pid, 0)[1:]
        proc.returncode = 0
    assert usage.ru_maxrss < 200_000, f"{usage.ru_maxrss} KiB"  # Linux: KiB
    longest = max(len(line) for line in out.open("rb"))
    assert longest < 64_000, longest
