"""`appmode board --pty --profile minibalance` driven through the wire by appmode's own
commands, in real time: what docs/protocol.md §13 says a host meets on a real board."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from appmode.protocol.transcript import read_transcript
from appmode.transcript.runner import run_live, run_virtual
from tests.support.processes import ROOT, BoardProcess, board_process, run

MINIBALANCE_SUITE = sorted((ROOT / "appmode" / "transcript" / "suite" / "minibalance").glob("*"))


@pytest.fixture(scope="module")
def board() -> Iterator[BoardProcess]:
    with board_process("--pty", "--profile", "minibalance", "--quiet") as served:
        yield served


@pytest.mark.parametrize("path", MINIBALANCE_SUITE, ids=lambda p: p.name)
def test_s13_suite_passes_on_virtual_time(path: Path) -> None:
    result = run_virtual(read_transcript(path))
    assert result.passed, result.failure


@pytest.mark.parametrize(
    "name",
    ["s13_set_value_arithmetic", "s13_telemetry_period", "s13_frame_stops_the_car"],
)
def test_s13_suite_passes_in_real_time_over_a_pty(board: BoardProcess, name: str) -> None:
    path = ROOT / "appmode" / "transcript" / "suite" / "minibalance" / f"{name}.transcript"
    result = run_live(read_transcript(path), board.url)
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
    done = run("send", board.url, "--raw", "{0:75207}")
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
