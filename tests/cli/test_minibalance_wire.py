"""`appmode board --pty --profile minibalance` driven through the wire by appmode's own
commands, in real time: what docs/protocol.md §13 says a host meets on a real board.
Three of the profile's transcripts run in real time with the rest of the suite
(tests/transcript/test_conformance.py)."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from appmode.transcript.reading import read_transcript
from appmode.transcript.runner import run_virtual
from tests.support.processes import ROOT, BoardProcess, board_process, run

BOOT = 2.0
"""Seconds the firmware takes to boot: records from 1.4 s, motors from 1.9 s (§13.1)."""
MINIBALANCE_SUITE = sorted((ROOT / "transcripts" / "suite" / "minibalance").glob("*"))


@pytest.fixture(scope="module")
def board() -> Iterator[BoardProcess]:
    with board_process("--pty", "--profile", "minibalance", "--quiet") as served:
        time.sleep(BOOT)
        yield served


@pytest.mark.parametrize("path", MINIBALANCE_SUITE, ids=lambda p: p.name)
def test_s13_suite_passes_on_virtual_time(path: Path) -> None:
    result = run_virtual(read_transcript(path))
    assert result.passed, result.failure


def test_s13_params_reads_the_factory_defaults(board: BoardProcess) -> None:
    done = run("params", board.url, "--json")
    assert done.returncode == 0, done.stderr
    values = json.loads(done.stdout)
    assert values["max_speed"] == 30 and values["max_position"] == 3000
    assert values["position_kp"] == 40


def test_s13_a_set_the_board_changes_or_ignores_fails_saying_what_it_did(
    board: BoardProcess,
) -> None:
    done = run("params", board.url, "--set", "max_speed=10")
    assert done.returncode == 2
    assert "the board set max_speed to 15 instead" in done.stderr
    done = run("params", board.url, "--set", "gyro_compensation=5")
    assert done.returncode == 2
    assert "the board ignored it: gyro_compensation is still 0" in done.stderr
    assert run("params", board.url, "--set", "max_speed=30").returncode == 0


def test_s13_an_out_of_range_value_is_shown_and_repaired(board: BoardProcess) -> None:
    done = run("send", board.url, "--raw", "{0:75207}", "--profile", "minibalance")
    assert done.returncode == 0, done.stderr
    shown = run("params", board.url)
    assert shown.returncode == 0, "the read worked: the board holds that value"
    assert "75207" in shown.stdout and "out of range" in shown.stdout
    assert "repair it with --set max_speed=N" in shown.stderr
    fixed = run("params", board.url, "--set", "max_speed=30")
    assert fixed.returncode == 0, fixed.stderr
    assert "out of range" not in fixed.stdout


def test_s13_send_and_monitor_show_the_a_record_by_its_meaning(board: BoardProcess) -> None:
    done = run("send", board.url, "--profile", "minibalance", "{0:30}", "KJ", "A", "wait:1.0")
    assert done.returncode == 0, done.stderr
    assert "velocity abs_x=0 abs_y=21 battery=" in done.stdout, done.stdout[-600:]
    assert done.stdout.rstrip().endswith("stop")
    mon = run("monitor", board.url, "--profile", "minibalance", "--json", "--count", "4")
    rows = [json.loads(line) for line in mon.stdout.splitlines()]
    a = [r for r in rows if r["kind"] == "velocity"]
    assert a and set(a[0]) >= {"abs_x", "abs_y", "battery", "extra"} and "z" not in a[0]


def test_s13_reading_params_while_driving_stops_first_and_says_so(board: BoardProcess) -> None:
    script = b"drive A\nwait 0.5\nparams\nwait 0.8\nstatus\nquit\n"
    done = run("drive", board.url, "--profile", "minibalance", stdin=script)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "stopped: a minibalance car stops at every frame; drive again after it" in out
    assert "in force  Z stop" in out
    assert "|0.7x|" in out and "|0.7y|" in out


def test_reading_params_while_driving_a_sheet_board_says_what_a_real_car_would_do() -> None:
    done = run("drive", stdin=b"drive A\nwait 0.3\nparams\nwait 0.3\nstatus\nquit\n")
    assert done.returncode == 0, done.stderr
    assert "note: on a minibalance car (--profile) this frame would stop it" in done.stdout
    assert "in force  A forward" in done.stdout, "the sheet board keeps driving"


def test_s13_a_session_left_on_the_direction_page_mid_rotation_stops_the_car(
    tmp_path: Path,
) -> None:
    """A button-page rotation goes on after J and Z (§13): the session's end must end it,
    judged by the board's own B records (the yaw stops changing)."""
    log_file = tmp_path / "board.transcript"
    served = BoardProcess("--pty", "--profile", "minibalance", "--quiet", "--record", str(log_file))
    try:
        script = b"page button\ndrive C\nwait 1\npage joystick\nwait 0.2\nquit\n"
        done = run("drive", served.url, "--profile", "minibalance", stdin=script)
        assert done.returncode == 0, done.stderr
        time.sleep(2.6)
    finally:
        served.stop()
    entries = read_transcript(log_file).entries
    sent = [e for e in entries if e.direction == ">"]
    assert sent[-1].text == "Z", sent[-4:]
    rotation = max(i for i, e in enumerate(sent) if e.text == "C")
    if "Z" not in [e.text for e in sent[rotation:-1]]:  # the stop guard may have stopped it
        assert [e.text for e in sent[-3:-1]] == ["K", "J"], sent[-4:]  # (a loaded machine)
    end = sent[-1].time
    yaws = [
        (e.time, int(e.text[2:-2].split(":")[2]))
        for e in entries
        if e.direction == "<" and e.text.startswith("{B")
    ]
    settled = [yaw for t, yaw in yaws if t > end + 1.2]
    assert len(settled) >= 5 and len(set(settled)) == 1, yaws[-12:]
