"""`appmode drive --uart2`: the console over the control port, alone and with the APP
port of the same board; script mode, the panel, and tmux against a board process."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest
from prompt_toolkit.utils import get_cwidth

from appmode.console.panel import status_fragments
from appmode.host.app.state import HostState
from appmode.host.events import BoardWarning
from appmode.protocol.directions import MOTIONS
from appmode.protocol.params import DriveType
from appmode.session.control.motion import velocity_for
from appmode.session.hold import HoldToDrive
from appmode.session.rows import WIDTH
from tests.console.test_console_tmux import (
    SESSION,
    _alive,
    appmode_in_tmux,
    screen,
    tmux,
    wait_screen,
)
from tests.support.processes import board_process, run, wait_for
from tests.support.sessions import session as open_board

STOP_FRAME = "FF FE 01 00 00 00 00 00 00 00"


def uart2_sent(record: Path) -> list[str]:
    """The `2>` payloads of a transcript, in order."""
    lines = record.read_text().splitlines()
    return [line.split(" ", 2)[2] for line in lines if line.split(" ")[1:2] == ["2>"]]


def test_each_motion_becomes_the_velocity_fields_of_each_drive_type() -> None:
    forward, right, cw = MOTIONS["forward"], MOTIONS["right"], MOTIONS["rotate-cw"]
    assert velocity_for(forward, 300, DriveType.MECANUM) == {"x": 0, "y": 300, "z": 0}
    assert velocity_for(right, 300, DriveType.OMNI) == {"x": 300, "y": 0, "z": 0}
    assert velocity_for(cw, 250, DriveType.MECANUM) == {"x": 0, "y": 0, "z": 250}
    assert velocity_for(forward, 400, DriveType.DIFF) == {"y": 400, "z": 0}
    assert velocity_for(cw, 400, DriveType.DIFF_GYRO) == {"left": 400, "right": -400}
    front_right = MOTIONS["front-right"]  # y + z/2 on a diff car: capped at full duty
    assert velocity_for(front_right, 800, DriveType.DIFF_GYRO) == {"left": 1000, "right": 400}


def test_script_mode_drives_turns_and_sets_over_the_embedded_control_port(tmp_path: Path) -> None:
    record = tmp_path / "u2.transcript"
    script = (
        b"drive forward\nwait 0.8\nstatus\nstop\nset max_speed 800\nread max_speed\n"
        b"rotate 30\nwait 1.5\nset max_speed 70000\nfly\nquit\n"
    )
    done = run("drive", "--uart2", "--keep-going", "--record", str(record), stdin=script)
    assert done.returncode == 1, done.stderr  # two lines failed, on purpose
    out = done.stdout
    assert "SIMULATED BOARD" in out and "sim://?port=uart2" in out
    assert re.search(r"control\s+UART2\s+drives", out) and "drive omni" in out
    assert re.search(r"in force\s+forward", out), (out, done.stderr)
    wheel_a = re.search(r"wheels\s+A (-?\d+)/(-?\d+)", out)
    assert wheel_a and int(wheel_a.group(1)) == 260 and int(wheel_a.group(2)) > 200, out
    assert "set max_speed = 800 (verified)" in out and "max_speed = 800" in out
    assert re.search(r"rotated 30° in \d\.\d\d s", out)
    assert "appmode: error: max_speed" in done.stderr  # out of range: nothing sent
    assert "appmode: error: unknown command 'fly'" in done.stderr
    assert "not saved: max_speed 500 → 800" in done.stderr
    sent = uart2_sent(record)
    assert "FF FE 01 00 00 01 2C 00 00 00" in sent  # forward at 300
    assert sent[-2:] == ["FF FE 80 80 09 00 00 00 00 00", STOP_FRAME]  # report off, stop


def test_both_ports_of_one_board_are_shown_and_recorded(tmp_path: Path) -> None:
    record = tmp_path / "both.transcript"
    script = b"drive forward\nwait 1\nstatus\nquit\n"
    done = run("drive", "sim://", "--uart2-url", "sim://", "--record", str(record), stdin=script)
    assert done.returncode == 0, done.stderr
    assert re.search(r"APP port\s+link up", done.stdout)
    velocity = re.search(r"velocity\s+x\s+0\s+y\s+(\d+)", done.stdout)
    assert velocity and int(velocity.group(1)) >= 250, done.stdout  # the A record follows
    lines = record.read_text().splitlines()
    assert any(" < {A" in line for line in lines) and any(" 2< 24 " in line for line in lines)
    assert uart2_sent(record)[-1] == STOP_FRAME


def test_the_panel_fits_80_columns_with_both_ports() -> None:
    url = "sim://?share=panel&drive=mecanum"
    session = open_board(url, HoldToDrive(latched=True), url2=url + "&port=uart2")
    try:
        session.start()
        end = time.monotonic() + 1.5
        while time.monotonic() < end:
            if session.drive is not None and session.in_force == "stop":
                session.press("front-right")
            session.tick()
            time.sleep(0.02)
        lines = "".join(part[1] for part in status_fragments(session)).splitlines()
        help_lines = session.help_lines
    finally:
        session.close()
    for line in [*lines, *help_lines]:
        assert sum(get_cwidth(ch) for ch in line) <= WIDTH, line
    assert len(lines) + 1 + 3 <= 24, lines  # + the rule and three message lines
    text = "\n".join(lines)
    assert "drive mecanum" in text and "in force  front-right" in text, text
    assert re.search(r"wheels\s+A 600/\d+  B 0/\d+  C 600/\d+  D 0/\d+", text), text


def test_the_app_console_says_when_its_letters_are_not_followed() -> None:
    state = HostState()
    state.sent(b"A", 0.0)
    still = b"{A0:0:0:0}$"  # the car stands still
    assert not state.feed(still, 0.5)[1:]
    warning = state.feed(still, 1.1)[-1]
    assert state.letters_ignored
    assert isinstance(warning, BoardWarning) and "UART2" in warning.text
    assert not state.feed(still, 1.2)[1:]  # said once


@pytest.mark.timing
def test_the_console_over_uart2_in_tmux_leaves_the_stop_frame_last(tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--record", str(record), "--quiet", "--drive", "mecanum") as board:
        command = appmode_in_tmux(f"drive {board.uart2} --uart2")
        tmux("new-session", "-d", "-s", SESSION, "-x", "100", "-y", "30", command)
        try:
            wait_screen(r"REAL BOARD")
            wait_screen(r"settings\s+max_speed 500")
            wait_screen(r"wheels\s+A 0/0")  # the encoder report is on
            # held, as a person holds it until the car moves: keys repeat every 30 ms
            # until the wheels show past 200 (a loaded machine reads and shows it later)
            moving = r"wheels\s+A 300/(20[1-9]|2[1-9]\d|[3-9]\d\d)"
            pressed = time.monotonic()
            while not re.search(moving, screen()):
                assert time.monotonic() - pressed < 10, screen()
                for _ in range(4):
                    tmux("send-keys", "-t", SESSION, "Up")
                    time.sleep(0.03)
            wait_screen(r"in force\s+stopped", timeout=2)  # released: the zero frame
            tmux("send-keys", "-t", SESSION, "-l", "r")
            wait_screen(r"rotated 90° in", timeout=15)  # the board polled for its angle left
            tmux("send-keys", "-t", SESSION, ":")
            tmux("send-keys", "-t", SESSION, "set max_speed 800", "Enter")
            wait_screen(r"set max_speed = 800 \(verified\)")
            tmux("send-keys", "-t", SESSION, "-l", "w")  # hold again, then close the terminal
            pid = int(tmux("display-message", "-p", "-t", SESSION, "#{pane_pid}").strip())
        finally:
            tmux("kill-session", "-t", SESSION)  # a closed terminal: SIGHUP
        wait_for(lambda: not Path(f"/proc/{pid}").exists())
        assert not _alive()
    sent = uart2_sent(record)
    assert "FF FE 01 00 00 01 2C 00 00 00" in sent and sent[-1] == STOP_FRAME, sent[-4:]


def test_the_app_console_shows_a_take_over_by_another_program() -> None:
    with board_process("--pty", "--quiet") as board:
        taken = run("send", board.uart2, "--uart2", "--no-report", "stop")
        assert taken.returncode == 0, taken.stderr
        done = run("drive", board.url, stdin=b"drive A\nwait 1.6\nstatus\nquit\n")
    assert done.returncode == 0, done.stderr
    assert "WARNING: the car stands still" in done.stdout
    assert re.search(r"control\s+the car does not follow the letters\s+UART2", done.stdout)


def test_frames_sent_by_command_show_as_the_frame_in_force() -> None:
    done = run("drive", "--uart2", stdin=b"send velocity:0,300,0\nstatus\nstop\nstatus\n")
    assert done.returncode == 0, done.stderr
    forces = re.findall(r"in force\s+(\w[\w ]*?)\s{2,}", done.stdout)
    assert forces == ["velocity 0 300 0", "stopped"], done.stdout


def test_the_uart2_consoles_help_fits_80_by_24_and_scrolls() -> None:
    """Issue 23.3: at 80×24 the help hid its own close key, ran columns together, and
    PgUp scrolled the messages under it; `v` did nothing, silently."""
    command = appmode_in_tmux("drive --uart2")
    tmux("new-session", "-d", "-s", SESSION, "-x", "80", "-y", "24", command)
    try:
        wait_screen(r"settings\s+max_speed 500")
        tmux("send-keys", "-t", SESSION, "v")
        wait_screen(r"no waveforms on the control port's console")
        tmux("send-keys", "-t", SESSION, "?")
        shown = wait_screen(r"help · \? or Esc close · PgUp/PgDn scroll").string
        assert re.search(r"velocity X Y Z\|L R  +send a velocity frame", shown), shown
        assert re.search(r"quit\s+stop the car and leave", shown), "all of it, close key too"
        assert all(len(line) <= 80 for line in shown.splitlines())
        tmux("send-keys", "-t", SESSION, "PageUp")
        assert "lines back" not in screen(), "PgUp moves the help, not the messages"
        tmux("send-keys", "-t", SESSION, "Escape")
        wait_screen(r"settings\s+max_speed 500")
    finally:
        tmux("kill-session", "-t", SESSION)


def test_the_uart2_console_drives_a_board_that_answers_no_reads() -> None:
    """Issue 24.4: against a minibalance board the UART2 console failed at its start,
    reading settings the reference firmware never answers."""
    script = b"wait 2\ndrive forward\nwait 0.5\nstatus\nquit\n"
    done = run("drive", "sim://?profile=minibalance&port=uart2", "--uart2", stdin=script)
    assert done.returncode == 0, done.stderr
    assert "this board answers no reads" in done.stdout
    assert re.search(r"in force\s+forward", done.stdout) and "drive omni" in done.stdout
    assert re.search(r"errors 0", done.stdout), "its status bursts are no errors"


def test_the_in_force_line_fits_80_columns_whatever_is_in_force() -> None:
    """Issue 23.3: a long frame in force pushed the keys' line past 80 columns."""
    script = b"speed 65535\nangle 359.5\nsend FFFE03FFFFFFFFFFFF07\nwait 0.3\nstatus\nstop\nquit\n"
    done = run("drive", "--uart2", stdin=script)
    assert done.returncode == 0, done.stderr
    assert "position x=-65535 y=-65535 z=-65535" in done.stdout
    assert "speed 65535 · r/R 359.5° · latched" in done.stdout
    assert max(get_cwidth(line) for line in done.stdout.splitlines()) <= WIDTH
