"""`params`, `send` and `monitor` with --uart2 against a served board, in real time: the
issue's "done when", and the stop frame last whatever ends a session."""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

from appmode.protocol import app, app_decoders, control
from appmode.transcript.reading import read_transcript
from tests.support.processes import appmode_cmd, board_process, run

STOP = control.STOP.hex(" ").upper()


def uart2_lines(record: Path, direction: str) -> list[str]:
    return [
        line.split(" ", 2)[2]
        for line in record.read_text().splitlines()
        if line.split(" ")[1:2] == [direction]
    ]


def test_params_set_save_and_the_setting_is_there_after_a_restart(tmp_path: Path) -> None:
    flash = tmp_path / "flash.json"
    with board_process("--pty", "--flash", str(flash)) as board:
        done = run("params", board.uart2, "--uart2", "--set", "max_speed=800", "--save")
        assert done.returncode == 0, done.stderr
        rows = {line.split()[1]: line.split()[2] for line in done.stdout.splitlines()[1:]}
        assert len(rows) == 10 and rows["max_speed"] == "800"
        assert "set max_speed = 800 (verified)" in done.stderr
        assert "does not confirm a save" in done.stderr
    with board_process("--pty", "--flash", str(flash)) as board:
        done = run("params", board.uart2, "--uart2", "--json")
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["max_speed"] == 800


def test_send_velocity_shows_reports_the_app_port_follows_and_the_stop_is_last(
    tmp_path: Path,
) -> None:
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--drive", "mecanum", "--record", str(record)) as board:
        done = run("send", board.uart2, "--uart2", "velocity:0,300,0", "wait:1")
        assert done.returncode == 0, done.stderr
    reports = [line for line in done.stdout.splitlines() if " 2< 24 " in line]
    assert len(reports) >= 15, "encoder reports every 50 ms"
    assert "encoders A=300/" in reports[-1]
    last = done.stdout.splitlines()[-1]
    assert " 2> " + STOP in last and "velocity 0 0 0" in last
    assert uart2_lines(record, "2>")[-1] == STOP, "the board's last UART2 frame is the stop"
    transcript = read_transcript(record)
    ys = [
        e.y
        for entry in transcript.entries
        if entry.direction == "<"
        for e in app_decoders.BoardDecoder().feed(entry.data)
        if isinstance(e, app.Velocity)
    ]
    assert max(ys) >= 290, "the APP port's A record follows the velocity frame"


def test_sigterm_and_sighup_during_send_leave_the_stop_frame_last(tmp_path: Path) -> None:
    for sig in (signal.SIGTERM, signal.SIGHUP):
        record = tmp_path / f"{sig}.transcript"
        with board_process("--pty", "--record", str(record)) as board:
            proc = subprocess.Popen(
                appmode_cmd("send", board.uart2, "--uart2", "velocity:0,300,0", "wait:30"),
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            time.sleep(2.0)
            proc.send_signal(sig)
            _, err = proc.communicate(timeout=20)
            assert "Traceback" not in err
            time.sleep(0.3)
        assert uart2_lines(record, "2>")[-1] == STOP, sig


def test_bad_tokens_and_values_are_one_line_before_anything_is_sent() -> None:
    for args in (
        ["send", "sim://", "--uart2", "velocity:0,x,0"],
        ["send", "sim://", "--uart2", "bogus"],
        ["send", "sim://", "--uart2", "set:max_speed=70000"],
        ["params", "sim://", "--uart2", "--set", "max_speed=70000"],
        ["params", "sim://", "--uart2", "--set", "nosuch=1"],
        ["params", "sim://", "--load"],
        ["monitor", "sim://", "--uart2", "--filter", "A"],
    ):
        done = run(*args)
        assert done.returncode == 2, (args, done.stderr)
        assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr, args


def test_monitor_prints_reports_as_json_lines_and_sends_nothing() -> None:
    done = run("monitor", "sim://?drive=mecanum", "--uart2", "--json", "--duration", "0.5")
    assert done.returncode == 0, done.stderr
    assert done.stdout == "", "no report unless turned on; a monitor sends nothing"
    assert "0 replies and reports" in done.stderr


def test_send_uart2_says_why_each_read_goes_twice() -> None:
    """Issue 69.9: `send --uart2` showed `read system_mode` twice, unexplained."""
    done = run("send", "sim://", "--uart2", "stop")
    assert done.returncode == 0, done.stderr
    reads = [line.split(None, 2)[2] for line in done.stdout.splitlines() if "read " in line]
    assert reads[:2] == ["FF FE 80 80 19 00 00 00 00 00      read system_mode",
                         "FF FE 80 80 19 00 00 00 00 00      read system_mode again"]  # fmt: skip
    assert done.stderr.count("UART2 has no checksum, so two replies must agree") == 1
