"""The commands with `--chassis`, as a user runs them: decode, send, monitor, drive's
session, the board's chassis line and its recording, and the mistakes said in a line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from appmode.protocol import chassis
from appmode.protocol.twist import Twist
from tests.support.processes import board_process, run


def quick(tmp_path: Path) -> str:
    path = tmp_path / "quick.toml"
    path.write_text(
        'name = "quick"\nlike = "wheeltec-mec"\n[chassis]\nkind = "mec"\nboot_ms = 300\n'
    )
    return str(path)


def test_decode_chassis_prints_a_line_per_frame_in_si_and_names_bad_ones(tmp_path: Path) -> None:
    good = chassis.status(0, (300, 0, -500), (0, 0, 16384), (0, 0, -1877), 11800)
    bad = bytearray(good)
    bad[3] ^= 1
    capture = tmp_path / "capture.bin"
    capture.write_bytes(b"\x00\x01" + good[:9] + good + bytes(bad) + good + good[:5])
    done = run("decode", "--chassis", str(capture))
    assert done.returncode == 0, done.stderr
    lines = [json.loads(line) for line in done.stdout.splitlines()]
    kinds = [line["kind"] for line in lines]
    assert kinds == ["garbage", "chassis_status", "garbage", "chassis_status", "garbage"]
    assert lines[1]["forward"] == 0.3 and lines[1]["turn"] == -0.5 and lines[1]["volts"] == 11.8
    assert "wrong XOR" in lines[2]["reason"] and lines[-1]["reason"] == "a frame cut off"
    host = run("decode", "--chassis", "--from", "host", stdin=chassis.command(Twist(0.1)))
    assert json.loads(host.stdout)["kind"] == "chassis_command"


def test_the_board_serves_a_chassis_port_and_records_it(tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--profile", quick(tmp_path), "--record", str(record)) as board:
        assert board.chassis is not None and board.chassis.startswith("/dev/")
        done = run(
            "send", board.chassis, "--chassis", "--profile", quick(tmp_path),
            "wait:0.4", "velocity:0.2,0,0", "wait:0.5", "--json", "--listen", "0",
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
    statuses = [json.loads(line) for line in done.stdout.splitlines()]
    assert max(s["forward"] for s in statuses) == pytest.approx(0.2, abs=0.01)
    sent = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " c> " in line]
    assert sent[0] == chassis.command(Twist(0.2)).hex(" ").upper()
    assert sent[-1] == chassis.STOP.hex(" ").upper(), "the board's last frame is the stop"
    dumped = run("dump", str(record), "--profile", quick(tmp_path))
    assert dumped.returncode == 0, dumped.stderr
    assert "velocity +0.20 m/s" in dumped.stdout and "status" in dumped.stdout


def test_monitor_chassis_counts_status_frames() -> None:
    done = run("monitor", "sim://?profile=wheeltec-akm", "--chassis", "--count", "5")
    assert done.returncode == 0, done.stderr
    assert done.stdout.count(" c< ") == 5 and "status STOP" in done.stdout
    assert "monitor: 5 status frames, 0 errors" in done.stderr


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["send", "sim://", "--chassis", "--uart2", "stop"], "--chassis drives"),
        (["send", "sim://?profile=sheet", "--chassis", "stop"], "has no chassis port"),
        (["send", "sim://?port=uart2", "--chassis", "stop"], "names the board's uart2 port"),
        (["send", "sim://", "--chassis", "velocity:1e9"], "no car's"),
        (["send", "sim://", "--chassis", "velocity:a,b"], "velocity takes FORWARD"),
        (["send", "sim://", "--chassis", "--raw", "stop"], "not with --chassis"),
        (["decode", "--chassis", "--profile", "sheet"], "leave it out with --chassis"),
        (["board", "--listen-chassis", "127.0.0.1:0"], "has no chassis port"),
    ],
)
def test_mistakes_are_one_line(args: list[str], said: str) -> None:
    done = run(*args)
    assert done.returncode != 0
    assert said in done.stderr and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("profile", ["wheeltec-mec", "wheeltec-akm", "wheeltec-diff"])
def test_conform_chassis_passes_the_shipped_dialect_suite(profile: str) -> None:
    done = run("conform", "--chassis", "--profile", profile)
    assert done.returncode == 0, done.stdout + done.stderr
    counts = done.stdout.strip().splitlines()[-1]
    assert counts.startswith(("3 passed, 0 failed", "1 passed, 0 failed")), counts
    assert f"({profile} profile)" in counts


@pytest.mark.slow
def test_conform_chassis_runs_in_real_time_against_a_board(tmp_path: Path) -> None:
    suite = Path(__file__).parents[2] / "transcripts" / "suite" / "wheeltec"
    one = suite / "s15_3_bad_frames_dropped.transcript"
    done = run("conform", "--chassis", "--board", "sim://", str(one), timeout=90)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 passed, 0 failed against sim://?profile=wheeltec-mec&port=chassis" in done.stdout


def test_a_chassis_line_is_hex_pairs(tmp_path: Path) -> None:
    bad = tmp_path / "bad.transcript"
    bad.write_text("# appmode transcript v1\n0.1 c< {A0:0:0:0}$\n")
    done = run("dump", str(bad))
    assert done.returncode != 0 and "as a chassis port's lines are" in done.stderr


def test_record_chassis_writes_the_status_frames(tmp_path: Path) -> None:
    out = tmp_path / "status.transcript"
    done = run("record", "sim://?profile=wheeltec-diff", "--chassis", str(out), "--count", "4")
    assert done.returncode == 0, done.stderr
    lines = [line for line in out.read_text().splitlines() if " c< " in line]
    assert len(lines) == 4 and all(line.endswith(" 7D") for line in lines)
    assert "record: 4 status frames, 0 errors" in done.stderr


def test_doctor_recognises_a_chassis_port(tmp_path: Path) -> None:
    with board_process("--pty", "--profile", "wheeltec-akm") as board:
        assert board.chassis is not None
        done = run("doctor", board.chassis, "--json")
    assert done.returncode == 0, done.stderr
    (finding,) = [json.loads(line) for line in done.stdout.splitlines()]
    assert finding["kind"] == "chassis" and finding["car"] and finding["baud"] == 115200
    assert "--chassis --profile wheeltec-mec, wheeltec-akm or wheeltec-diff" in finding["fix"]


def test_replay_chassis_plays_a_session_again_and_ends_with_a_zero_frame(tmp_path: Path) -> None:
    session = tmp_path / "session.transcript"
    done = run(
        "send", "sim://?profile=wheeltec-mec", "--chassis", "velocity:0.2,0,0.3", "wait:0.35",
        "stop", "--record", str(session), "--listen", "0",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    played = [line.split(" ", 2)[2] for line in session.read_text().splitlines() if " c> " in line]
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--profile", "wheeltec-mec", "--record", str(record)) as board:
        assert board.chassis is not None
        again = run("replay", str(session), "--to", board.chassis, "--chassis")
        assert again.returncode == 0, again.stderr
    got = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " c> " in line]
    assert got[: len(played)] == played
    assert got[-1] == chassis.STOP.hex(" ").upper(), "the replay, a host, ends with the stop"
    assert f"replayed {len(played)} commands" in again.stderr


def test_plot_draws_a_chassis_transcript(tmp_path: Path) -> None:
    session = tmp_path / "session.transcript"
    done = run(
        "send", "sim://?profile=wheeltec-mec", "--chassis", "velocity:0.2", "wait:0.3",
        "--record", str(session), "--listen", "0",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    image = tmp_path / "session.png"
    drawn = run("plot", str(session), "-o", str(image))
    assert drawn.returncode == 0, drawn.stderr
    assert image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and image.stat().st_size > 20_000


def test_dump_plot_and_doctor_take_chassis_too(tmp_path: Path) -> None:
    session = tmp_path / "session.transcript"
    done = run(
        "send", "sim://?profile=wheeltec-mec", "--chassis", "velocity:0.2", "wait:0.2",
        "--record", str(session), "--listen", "0",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    session.write_text(session.read_text() + "0.9000 > Z\n")  # an APP line, not shown
    dumped = run("dump", str(session), "--chassis", "--json")
    directions = {json.loads(line)["dir"] for line in dumped.stdout.splitlines()}
    assert dumped.returncode == 0 and directions == {"c>", "c<"}, dumped.stderr
    image = tmp_path / "status.png"
    assert run("plot", str(session), "--chassis", "-o", str(image)).returncode == 0
    assert image.read_bytes()[:4] == b"\x89PNG"
    app_only = tmp_path / "app.transcript"
    app_only.write_text("# appmode transcript v1\n0.0 < {A0:0:0:0}$\n0.1 < {A0:0:0:0}$\n")
    refused = run("plot", str(app_only), "--chassis", "-o", str(tmp_path / "x.png"))
    assert refused.returncode == 2 and "no chassis status frames" in refused.stderr
    with board_process("--pty", "--profile", "wheeltec-diff") as board:
        assert board.chassis is not None
        found = run("doctor", board.chassis, board.url, "--chassis", "--json")
    kinds = [json.loads(line)["kind"] for line in found.stdout.splitlines()]
    assert kinds == ["chassis", "no chassis"], found.stdout
