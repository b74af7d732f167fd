"""Whatever ends a host session, the car is stopped (docs/protocol.md §2.1, §2.2).

SIGHUP (a closed terminal, a dropped SSH connection) ends every host command as SIGTERM
and Ctrl-C do, and a session that leaves a frame open ends it before its `Z`, which a
frame would otherwise swallow. Each test checks the board's own state afterwards.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
from functools import partial
from pathlib import Path

import pytest
import serial

from appmode.host.app.client import Host
from appmode.ports.sim import SimSerial
from appmode.ports.target import Target
from appmode.protocol import params
from tests.support.processes import (
    ROOT,
    appmode_cmd,
    board_process,
    board_state,
    run,
    sent_lines,
    wait_for,
)

STOPPED = (0, 0, 0)
DEFAULTS = tuple(params.DEFAULTS)

LONG_REPLAY = "# appmode transcript v1\n0.000 > J\n0.050 > A\n30.000 > Z\n"
OPEN_FRAME_REPLAY = "# appmode transcript v1\n0.000 > J\n0.050 > A\n0.100 > {0:8\n"


def _start(args: list[str], stdin: bytes = b"", traceback: bool = False) -> subprocess.Popen[bytes]:
    """`appmode ARGS` started (`traceback`: a bug prints its traceback, for the report)."""
    proc = subprocess.Popen(
        appmode_cmd(*args),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=ROOT,
        env={**os.environ, "APPMODE_TRACEBACK": "1"} if traceback else None,
    )
    assert proc.stdin is not None
    proc.stdin.write(stdin)
    proc.stdin.flush()
    return proc


@pytest.mark.parametrize("command", ["send", "drive", "replay"])
def test_sighup_ends_a_host_command_with_the_car_stopped(command: str, tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    replay = tmp_path / "long.transcript"
    replay.write_text(LONG_REPLAY)
    with board_process("--pty", "--record", str(record), "--quiet") as board:
        args, stdin = {
            "send": (["send", board.url, "J", "A", "wait:30"], b""),
            "drive": (["drive", board.url], b"drive A\nwait 30\n"),
            "replay": (["replay", str(replay), "--to", board.url], b""),
        }[command]
        proc = _start(args, stdin)
        try:
            wait_for(lambda: record.exists() and "A" in sent_lines(record))
            proc.send_signal(signal.SIGHUP)
            proc.communicate(timeout=10)
        finally:
            proc.kill()
        sent = sent_lines(record)
        assert sent[-1] == "Z", sent[-5:]
        assert board_state(board.url) == (STOPPED, DEFAULTS)


def test_sighup_ends_monitor_with_its_summary(tmp_path: Path) -> None:
    with board_process("--pty", "--quiet") as board:
        proc = _start(["monitor", board.url])
        try:
            assert proc.stdout is not None
            proc.stdout.readline()  # a record came: monitoring
            proc.send_signal(signal.SIGHUP)
            _, err = proc.communicate(timeout=10)
        finally:
            proc.kill()
    assert "monitor: " in err.decode() and " record" in err.decode()
    assert "Traceback" not in err.decode()


def _tap_session(tmp_path: Path, app_bytes: bytes, sig: int) -> list[str]:
    """An app writes `app_bytes` through `tap`, which then gets `sig`: what the board
    received, and its state afterwards must be stopped with its parameters untouched."""
    record = tmp_path / "tap.transcript"
    with board_process("--pty", "--quiet") as board:
        proc = _start(["tap", "pty", board.url, "--record", str(record), "--quiet"])
        try:
            assert proc.stdout is not None
            app_side = proc.stdout.readline().decode().removeprefix("port: ").strip()
            with serial.Serial(app_side, 9600, timeout=0.1) as app:
                app.write(app_bytes)
                wait_for(lambda: record.exists() and "A" in sent_lines(record))
                time.sleep(0.3)  # an open frame is held by the recorder, not yet written
                proc.send_signal(sig)
                proc.communicate(timeout=10)
        finally:
            proc.kill()
        assert board_state(board.url) == (STOPPED, DEFAULTS)
    return sent_lines(record)


def test_sighup_ends_tap_with_the_car_stopped(tmp_path: Path) -> None:
    assert _tap_session(tmp_path, b"JA", signal.SIGHUP)[-1] == "Z"


def test_an_app_leaving_tap_inside_a_frame_leaves_the_car_stopped(tmp_path: Path) -> None:
    sent = _tap_session(tmp_path, b"JA{0:8", signal.SIGTERM)
    assert sent[-2:] == ["{}", "Z"] or sent[-1] == "{}Z"


@pytest.mark.parametrize(
    "tokens",
    [["J", "A", "\\x7b"], ["--raw", "J", "A", "{0:8"], ["--raw", "J", "A", "{Q:P"]],
    ids=["escaped-brace", "raw-set-frame", "read-frame"],
)
def test_send_ending_inside_a_frame_still_stops_the_car(tokens: list[str]) -> None:
    with board_process("--pty", "--quiet") as board:
        done = run("send", board.url, *tokens, "--listen", "0")
        assert done.returncode == 0, done.stderr
        # the open frame is abandoned, never applied: max_speed is still the default
        assert board_state(board.url) == (STOPPED, DEFAULTS)
    assert done.stdout.splitlines()[-1].split()[1:] == [
        ">",
        "{}Z",
        "closes",
        "the",
        "open",
        "frame,",
        "then",
        "stop",
    ], "the user sees how the car was stopped"


def test_send_prints_the_final_z_it_sends() -> None:
    done = run("send", "sim://", "J", "A", "--listen", "0")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1].split()[1:] == [">", "Z", "stop"]


def test_replay_ending_inside_a_frame_still_stops_the_car(tmp_path: Path) -> None:
    replay = tmp_path / "open.transcript"
    replay.write_text(OPEN_FRAME_REPLAY)
    with board_process("--pty", "--quiet") as board:
        done = run("replay", str(replay), "--to", board.url)
        assert done.returncode == 0, done.stderr
        assert board_state(board.url) == (STOPPED, DEFAULTS)


def test_host_close_ends_an_open_frame_then_stops() -> None:
    ports: list[SimSerial] = []

    def opener(url: Target) -> SimSerial:
        ports.append(SimSerial(url.url, timeout=0.05))
        return ports[-1]

    with Host("sim://?pace=0", opener=opener) as host:
        host.send(b"JA{0:8")
        host.poll(0.2)
        assert ports[0].board.direction != 0  # driving, inside a frame
    board = ports[0].board
    assert board.direction == 0
    assert board.params == list(DEFAULTS)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_in_the_middle_of_a_long_write_still_stops_the_car(
    sig: int, tmp_path: Path
) -> None:
    """Issue 22.1: a frame of 120,000 bytes is still being written (at 9600 bps) when the
    signal comes: the stop must close the part of it that did leave."""
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--record", str(record), "--quiet") as board:
        proc = _start(["send", "--raw", board.url, "J", "A", "{0:" + "1" * 120_000])
        try:
            wait_for(lambda: record.exists() and "A" in sent_lines(record))
            time.sleep(1.5)  # well into the frame
            proc.send_signal(sig)
            proc.communicate(timeout=10)
        finally:
            proc.kill()
        assert proc.returncode == 130
        # the host wrote no more than a chunk ahead of the line: the stop comes at once
        wait_for(lambda: sent_lines(record)[-1] in ("{}Z", "Z"), timeout=3.0)
        assert board_state(board.url) == (STOPPED, DEFAULTS)


def _signal_trials(tmp_path: Path, trials: range) -> list[str]:
    """`send … J A wait:5` against a board of its own, then SIGTERM and SIGHUP, once for
    each trial: what went wrong."""
    record = tmp_path / f"board-{trials.start}.transcript"
    wrong = []
    with board_process("--pty", "--record", str(record), "--quiet") as board:
        for count, trial in enumerate(trials):
            proc = _start(["send", board.url, "J", "A", "wait:5"], traceback=True)
            err = b""
            try:
                wait_for(lambda n=count: sent_lines(record).count("A") > n)
                proc.send_signal(signal.SIGTERM)
                if trial % 2:
                    time.sleep(0.001 * trial)  # the second lands at different points
                proc.send_signal(signal.SIGHUP)
                err = proc.communicate(timeout=10)[1]
            finally:
                proc.kill()
            # the board, busy beside other work, may read the host's last bytes after it exits
            with contextlib.suppress(AssertionError):
                wait_for(lambda: sent_lines(record)[-1] == "Z", timeout=3.0)
            if sent_lines(record)[-1] != "Z":
                wrong.append(f"trial {trial}: the car was left moving")
            if proc.returncode != 130:
                said = err.decode(errors="replace")[-1500:]
                wrong.append(f"trial {trial}: exit {proc.returncode}: {said}")
        if board_state(board.url) != (STOPPED, DEFAULTS):
            wrong.append(f"trials {trials}: the board is not still at its defaults")
    if sent_lines(record).count("Z") < len(trials):
        wrong.append(f"trials {trials}: fewer stops than sessions")
    return wrong


def test_two_ending_signals_at_once_still_stop_the_car(tmp_path: Path) -> None:
    """Issue 22.2: SIGTERM and SIGHUP together (as systemd sends them), the second while
    the first unwinds: every session still ends with its stop. Twelve, on three boards at
    once (they mostly wait)."""
    with ThreadPoolExecutor(3) as pool:
        wrong = pool.map(
            partial(_signal_trials, tmp_path), (range(0, 12, 3), range(1, 12, 3), range(2, 12, 3))
        )
        failures = [why for whys in wrong for why in whys]
    assert not failures, failures


def test_tap_stopped_during_a_burst_from_the_app_leaves_the_stop_last(tmp_path: Path) -> None:
    """Issue 22.3: an app writes J and 30,000 A through tap; SIGTERM. Forwarding ends
    first: nothing the app sent reaches the board after the tap's Z."""
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--record", str(record), "--quiet") as board:
        proc = _start(["tap", "pty", board.url, "--record", str(tmp_path / "tap.transcript")])
        try:
            assert proc.stdout is not None
            app_side = proc.stdout.readline().decode().removeprefix("port: ").strip()
            with serial.Serial(app_side, 9600, timeout=0.1, write_timeout=0) as app:
                with contextlib.suppress(serial.SerialTimeoutException):
                    app.write(b"J" + b"A" * 30_000)
                wait_for(lambda: sent_lines(record).count("A") > 200)
                proc.send_signal(signal.SIGTERM)
                _, err = proc.communicate(timeout=10)
        finally:
            proc.kill()
        assert "Traceback" not in err.decode()
        wait_for(lambda: sent_lines(record)[-1] == "Z", timeout=3)
        time.sleep(0.5)
        assert sent_lines(record)[-1] == "Z", "bytes reached the board after the stop"
        assert board_state(board.url) == (STOPPED, DEFAULTS)


def test_a_stop_swallowed_by_a_frame_another_program_left_open_is_sent_again() -> None:
    """Issue 22.4: `printf 'JA{Q:P'` from another program leaves a frame open, which
    swallows the session's Z: the host sees the car still moving on its A records,
    drops that frame unapplied, and stops again."""
    with board_process("--pty", "--quiet") as board:
        with serial.Serial(board.url, 9600) as other:
            other.write(b"JA{Q:P")
        time.sleep(0.5)
        done = run("send", board.url, "Z", "--listen", "0.3")
        assert done.returncode == 0, done.stderr
        assert "WARNING: the car still moved 1.5 s after the stop: sent {}KJZ" in done.stderr
        assert board_state(board.url) == (STOPPED, DEFAULTS)


def test_a_car_that_never_stops_is_said_to_be_maybe_moving(tmp_path: Path) -> None:
    """Issue 22.4: UART2 has taken over and drives; the APP port's stops cannot take.
    After a bounded number of tries: one line, exit 2."""
    with (
        board_process("--pty", "--quiet") as board,
        serial.Serial(board.uart2, 115200) as control,
    ):
        control.write(bytes.fromhex("FF FE 01 00 00 01 2C 00 00 00"))  # y = 300
        time.sleep(0.5)
        done = run("send", board.url, "J", "--listen", "0.2")
        control.write(bytes.fromhex("FF FE 01 00 00 00 00 00 00 00"))
    assert done.returncode == 2
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("appmode: error: the car may still be moving: it did not stop")
    assert "after 3 stops" in last and "UART2" in last
