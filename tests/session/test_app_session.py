"""`appmode drive` script mode and the session under a lost link."""

from __future__ import annotations

import errno
import io
import os
import re
import subprocess
import time
from pathlib import Path

import pytest

from appmode.console.script import command_lines
from appmode.protocol.recorder import Recorder
from appmode.session.command_line import MAX_COMMAND
from appmode.session.hold import HoldToDrive
from tests.support.processes import BoardProcess, appmode_cmd, run, sent_lines
from tests.support.sessions import session as open_board


def test_script_mode_reads_commands_from_stdin(tmp_path: Path) -> None:
    record = tmp_path / "s.transcript"
    script = b"set max_speed 800\ndrive A\nwait 0.6\nstatus\nspeed -300\nfly\nquit\n"
    done = run("drive", "--keep-going", "--record", str(record), stdin=script)
    assert done.returncode == 1, done.stderr  # `fly` failed
    out = done.stdout
    assert "max_speed = 800 (verified)" in out
    assert "SIMULATED BOARD" in out and "in force  A forward" in out
    assert "max_speed = 500 (verified)" in out
    assert "appmode: error: unknown command 'fly': type help for the list" in done.stderr
    sent = [line for line in record.read_text().splitlines() if " > " in line]
    assert sent[-1].endswith(" > Z"), sent[-3:]


def test_a_huge_command_line_is_refused_at_once() -> None:
    """5 MB on one line (a file piped in by mistake): one error, in time linear in it
    (splitting it into words would take hours), and the next line runs."""
    done = run("drive", "--keep-going", stdin=b"x" * 5_000_000 + b"\nstatus\n", timeout=30)
    assert done.returncode == 1
    assert done.stderr.startswith(
        "appmode: error: a command line of over 1,000 characters: a command is shorter "
        "(was a file given by mistake?)\n"
    )
    assert "SIMULATED BOARD" in done.stdout


def test_a_script_with_no_line_end_ends_at_its_first_line() -> None:
    """/dev/zero given as the script: its first 1,001 characters are refused at once, and
    the script ends there (it does not read on for the line's end, which never comes)."""
    with open("/dev/zero", "rb") as zero:
        done = subprocess.run(
            appmode_cmd("drive"), stdin=zero, capture_output=True, text=True, timeout=30
        )
    assert done.returncode == 1
    assert done.stderr.splitlines() == [
        "appmode: error: a command line of over 1,000 characters: a command is shorter "
        "(was a file given by mistake?)",
        "appmode: the script stopped at its first error (--keep-going runs on)",
    ]


@pytest.mark.parametrize("size", [999, 1000, 1001, 2002, 5000])
def test_a_script_line_is_never_held_whole(size: int) -> None:
    """command_lines holds at most MAX_COMMAND + 1 characters of a line: a line up to the
    limit comes whole, a longer one as its first MAX_COMMAND + 1 characters (refused
    then), and the line after it comes as it is."""
    lines = list(command_lines(io.StringIO("y" * size + "\nstatus\n"), MAX_COMMAND))
    assert lines[1:] == ["status\n"]
    assert lines[0].rstrip("\n") == "y" * min(size, MAX_COMMAND + 1)


def test_script_mode_against_a_board_process_over_tcp(tmp_path: Path) -> None:
    log_file = tmp_path / "board.transcript"
    board = BoardProcess("--listen", "0", "--quiet", "--record", str(log_file))
    try:
        done = run("drive", board.url, stdin=b"page button\ndrive C\nwait 0.3\n")
        assert done.returncode == 0, done.stderr
        assert "REAL BOARD" not in done.stdout  # no status asked for
    finally:
        board.stop()
    sent = [line.split(" ", 2)[2] for line in log_file.read_text().splitlines() if " > " in line]
    assert sent[:2] == ["J", "{Q:P}"] and "K" in sent and "C" in sent
    assert sent[-1] == "Z"


def test_keys_do_not_pretend_while_the_link_is_lost(tmp_path: Path) -> None:
    board = BoardProcess("--listen", "0", "--quiet")
    session = open_board(board.url, HoldToDrive())
    try:
        session.start()
        board.kill()
        end = time.monotonic() + 5
        while session.host.connected and time.monotonic() < end:
            session.tick()
            time.sleep(0.02)
        assert not session.host.connected
        for _ in range(30):  # a key held down repeats
            session.press("A")
        assert session.in_force == "Z"
        assert any("lost" in m for m in session.messages)
        assert session.messages[-1] == "link is down: not driving"
        assert list(session.messages).count("link is down: not driving") == 1, "said once"
    finally:
        session.close()


def test_help_lists_every_command() -> None:
    done = run("drive", stdin=b"help\n")
    for name in ("params", "set NAME VALUE", "save", "speed", "record FILE|stop", "quit"):
        assert name in done.stdout


def test_a_recording_that_fails_never_ends_the_session(tmp_path: Path) -> None:
    first, second = tmp_path / "first.transcript", tmp_path / "second.transcript"
    script = (
        f"record {first}\ndrive A\nwait 0.2\n"
        f"record {tmp_path}/no/such/folder.transcript\n"
        "record /dev/full\ndrive B\nwait 0.2\n"
        f"record {second}\ndrive C\nwait 0.2\nquit\n"
    )
    done = run("drive", "--keep-going", stdin=script.encode())
    assert done.returncode == 1, done.stderr
    assert f"{tmp_path}/no/such/folder.transcript: No such file or directory; still " in done.stderr
    assert "/dev/full: No space left on device; still recording to" in done.stderr
    assert sent_lines(first)[-2:] == ["A", "B"], "the first recording went on, then closed"
    assert sent_lines(second)[-2:] == ["C", "Z"]


class _FailingStream(io.StringIO):
    """A recording file on a disk that fills up after its header."""

    name = "full.transcript"

    def write(self, text: str) -> int:
        if self.getvalue():
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return super().write(text)


def test_a_recording_failing_midway_stops_with_a_message_and_driving_goes_on() -> None:
    session = open_board("sim://", HoldToDrive(latched=True))
    try:
        session.recorder = Recorder(_FailingStream())
        session.start()
        session.run("drive A")
        deadline = time.monotonic() + 2.0
        while session.recorder is not None and time.monotonic() < deadline:
            session.tick()  # a write is recorded once the reads have caught up with it
        assert session.recorder is None
        assert any(
            "cannot write transcript full.transcript: No space left on device; recording "
            "stopped" in m
            for m in session.messages
        )
        session.run("drive B")
        assert session.in_force == "B"
    finally:
        session.close()


def test_a_speed_step_past_the_range_says_what_it_set() -> None:
    done = run("drive", stdin=b"wait 0.3\nspeed -5000\nwait 0.5\nquit\n")
    assert done.returncode == 0, done.stderr
    assert "max_speed -4500 is out of 0–65535: setting 0" in done.stdout
    assert "max_speed = 0 (verified)" in done.stdout


def test_a_console_recording_has_the_times_the_board_took_its_bytes(tmp_path: Path) -> None:
    """On sim:// the console's recording stamps what it sends with the time the board took
    it, counted from the session's start, not with the console's clock after the write
    (under load those differ by ms, and a replay on virtual time then differs)."""
    record = tmp_path / "s.transcript"
    session = open_board("sim://", HoldToDrive(), str(record))
    port = session.host.link
    assert port is not None
    write = port.write

    def late_write(data: bytes) -> int:  # the console preempted after its write
        written = write(data)
        time.sleep(0.005)
        return int(written)

    port.write = late_write  # type: ignore[method-assign]
    try:
        time.sleep(0.2)
        session.run("drive A")
        took = port.written_at
        time.sleep(0.05)
    finally:
        session.close()
    stamps = [
        float(line.split(" ")[0]) for line in record.read_text().splitlines() if " > A" in line
    ]
    assert stamps[0] == took


def test_a_balance_car_s_session_shows_and_sets_its_own_fields(tmp_path: Path) -> None:
    """Issue 53.3: the console's panel, the page's instruments and the commands follow
    the profile: its B record by its fields, its gains in the user's units, no speed
    keys (it has no speed parameter)."""
    record = tmp_path / "s.transcript"
    script = (
        b"drive A\nwait 0.6\nstatus\nstop\nparams\nwait 0.5\nset balance_kp 0.42\n"
        b"wait 0.6\nstatus\nspeed +100\nquit\n"
    )
    done = run(
        "drive", "sim://?profile=balance", "--keep-going", "--record", str(record), stdin=script
    )
    assert done.returncode == 1, done.stderr  # the speed command
    out = done.stdout
    assert "attitude  balance angle" in out and "left encoder" in out and "right encoder" in out
    driving = re.search(r"\|1\.1 right\| +(\d+) +\|1\.1 left\| +(\d+)", out)
    assert driving and min(map(int, driving.groups())) > 100, out  # |1.1 × 100| soon
    assert "balance_kp = 0.42 (verified)" in out
    assert "balance_kp 0.42 · balance_kd 1 · velocity_kp 80" in out
    assert "battery   100 %" in out
    assert "the balance profile has no speed parameter: + and - change nothing" in done.stderr
    assert "note: on a minibalance car" not in out
    sent = [line.split(" > ")[1] for line in record.read_text().splitlines() if " > " in line]
    assert "{0:42}" in sent and sent[-1] == "Z"

    session = open_board("sim://?profile=balance", HoldToDrive(latched=True))
    try:
        session.start()
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            session.tick()
            shown = session.instruments()
            if shown.values_read and shown.telemetry and shown.telemetry.b:
                break
            time.sleep(0.05)
        t = shown.telemetry
        assert t is not None and not t.has_attitude and t.pitch is None
        assert [name for name, _ in t.b or ()] == [
            "balance angle", "left encoder", "right encoder"
        ]  # fmt: skip
        assert t.battery == 100 and [n for n, _ in t.motion or ()] == [
            "|1.1 right|", "|1.1 left|", "balance angle"
        ]  # fmt: skip
        assert shown.speed is None
        kp = shown.values[0]
        assert (kp.name, kp.value, kp.scale, kp.maximum) == ("balance_kp", 30000, 100, 2**31 - 1)
    finally:
        session.close()
