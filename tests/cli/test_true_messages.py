"""Issue 23.2 and 23.4: what appmode says is what happened; options do what they say."""

from __future__ import annotations

import os
from pathlib import Path

from appmode.board.firmware import Board
from appmode.protocol import params
from appmode.session.app.session import COMMANDS
from appmode.text import counted, wrapped
from tests.support.processes import run


def test_counts_agree_with_their_nouns() -> None:
    assert [counted(n, "error") for n in (0, 1, 2)] == ["0 errors", "1 error", "2 errors"]
    assert counted(1, "reply", "replies") == "1 reply"


def test_wrapped_lines_fit_and_keep_words_whole() -> None:
    text = "word " * 40 + "docs/protocol.md §12 'appmode send URL --uart2 wait:5'"
    lines = wrapped(text).splitlines()
    assert max(map(len, lines)) <= 80
    assert " ".join(line.strip() for line in lines) == text.strip()


def test_a_quiet_control_port_says_why() -> None:
    done = run("monitor", "sim://?port=uart2", "--uart2", "--duration", "0.3")
    assert done.returncode == 0, done.stderr
    assert "0 replies and reports, 0 errors" in done.stderr
    assert "encoder reports only while" in done.stderr and "system_mode bit 6" in done.stderr
    assert max(len(line) for line in done.stderr.splitlines()) <= 80


def test_quitting_the_embedded_board_unsaved_says_it_ends_with_the_session() -> None:
    done = run("drive", stdin=b"set max_speed 800\nquit\n")
    said = " ".join(done.stderr.split())
    assert "not saved: max_speed 500 → 800: the embedded board ends with this session" in said
    assert "switched off" not in done.stderr
    assert max(len(line) for line in done.stderr.splitlines()) <= 80, "issue 49.14: 83 columns"


def test_the_page_command_pairs_each_page_with_its_letter() -> None:
    page = next(spec for spec in COMMANDS if spec.name == "page")
    assert "direction (J), button (K), gravity (I)" in page.help


def test_the_board_log_shows_nine_parameters_saved_and_the_calibration_apart() -> None:
    board = Board()
    board.receive(b"{Q:W}", 0.1)
    (note,) = [n.text for n in board.take_notes()]
    assert note == f"{{Q:W}}: saved {list(params.DEFAULTS)} (gyro calibration 0)"


def test_options_are_taken_only_as_spelled() -> None:
    done = run("send", "--lis", "1", "sim://", "Z")
    assert done.returncode == 2 and "unrecognized arguments: --lis" in done.stderr
    done = run("drive", "--drive-t", "mecanum")
    assert done.returncode == 2 and "unrecognized arguments: --drive-t" in done.stderr


def test_drive_takes_the_drive_type_the_other_commands_take() -> None:
    done = run("drive", "--drive", "mecanum", stdin=b"status\nquit\n")
    assert done.returncode == 0, done.stderr
    assert "sim://?drive=mecanum" in done.stdout
    real = run("drive", "/dev/null", "--drive", "mecanum")
    assert real.returncode == 2 and "--drive on a real board's APP port" in real.stderr


def test_script_mode_errors_go_to_stderr_and_fail_the_script() -> None:
    done = run("drive", stdin=b"bogus\nset max_speed 800\nquit\n")
    assert done.returncode == 1
    assert "appmode: error: unknown command 'bogus'" in done.stderr
    assert "the script stopped at its first error" in done.stderr
    assert "error" not in done.stdout and "800" not in done.stdout, "nothing after it ran"
    going = run("drive", "--keep-going", stdin=b"set max_speed 70000\nset max_speed 800\n")
    assert going.returncode == 1 and "max_speed = 800 (verified)" in going.stdout
    assert "appmode: error: max_speed (parameter 0) must be in 0–65535" in going.stderr
    clean = run("drive", stdin=b"set max_speed 800\nset max_speed 500\n")
    assert clean.returncode == 0 and clean.stderr == "", clean.stderr


def test_script_mode_against_a_port_that_never_answers_fails(tmp_path: Path) -> None:
    import pty

    master, slave = pty.openpty()
    try:
        done = run("drive", os.ttyname(slave), stdin=b"status\n", timeout=60)
    finally:
        os.close(master)
        os.close(slave)
    assert done.returncode == 1
    assert "appmode: error: nothing came from" in done.stderr, done.stderr


def test_a_c_record_is_described_in_a_line_not_230_columns() -> None:
    """Issue 23.3: demo, send and dump printed every parameter by name after the record."""
    done = run("send", "sim://", "{Q:P}", "wait:0.2")
    (c_line,) = [line for line in done.stdout.splitlines() if "< {C" in line]
    assert c_line.endswith("params max_speed=500 …")
    assert len(c_line) <= 80


def test_each_parameter_table_says_what_its_numbers_are() -> None:
    """Issue 23.2: the APP table numbers 0-8, the UART2 table 1-10: each is the number its
    port's frames carry, and the tables and the help say so."""
    app_table = run("params", "sim://").stdout.splitlines()
    uart2_table = run("params", "sim://?port=uart2", "--uart2").stdout.splitlines()
    assert app_table[0].split()[:2] == ["n", "name"] and app_table[1].split()[0] == "0"
    assert uart2_table[0].split()[:2] == ["SS", "name"] and uart2_table[1].split()[0] == "1"
    helped = " ".join(run("params", "--help").stdout.split())
    assert "n is the index of the APP port's {n:value} frame (0-8)" in helped
    assert "SS is the setting's byte in the control port's FF FE 80 80 SS frame" in helped


def test_a_boards_start_up_text_shows_as_text_in_80_columns() -> None:
    done = run("demo", "--profile", "minibalance", "--fast")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert max(map(len, lines)) <= 80
    assert any(
        line.startswith("  0.500 < mpu_set_sensor\\x20complete")
        and line.endswith("… text, no record (64 bytes)")
        for line in lines
    )
    assert not any("undecodable" in line for line in lines)
