"""Issue 53: a profile that is only a file (the balance car, a user's own) — the
simulated board it gets, and the host's commands naming and scaling its fields."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from appmode.board.firmware import Board
from appmode.board.profiles import load, profile_named
from appmode.errors import AppmodeError
from appmode.protocol import app_decoders, param_values
from appmode.protocol.app import OtherRecord, ParamsRecord, Velocity
from appmode.transcript.reading import read_transcript
from tests.support.processes import ROOT, run

BALANCE = ROOT / "appmode" / "protocol" / "profiles" / "balance.toml"


def serve(board: Board, script: dict[int, bytes], ticks: int) -> bytes:
    """What the board sends over `ticks` steps of 50 ms, given `script[step]` as it goes."""
    out = b""
    for step in range(1, ticks + 1):
        now = step * 0.05
        board.advance(now)
        out += board.poll(now)
        if step in script:
            board.receive(script[step], now)
    return out


def test_the_balance_board_sends_its_records_and_stores_its_gains() -> None:
    board = Board(profile=profile_named("balance"))
    sent = serve(board, {4: b"A", 12: b"{0:42}{4:9}{Q:P}", 20: b"Z{Q:W}"}, 30)
    events = app_decoders.BoardDecoder(3).feed(sent)
    a = [e for e in events if isinstance(e, Velocity)]
    b = [e for e in events if isinstance(e, OtherRecord) and e.letter == "B"]
    c = [e for e in events if isinstance(e, ParamsRecord)]
    assert len(a) >= 10 and len(b) >= 10 and len(c) == 1
    assert all(len(e.values) == 3 for e in b)
    assert {e.z for e in a} == {100}, "the battery, in the A record's third field"
    moving = max(a, key=lambda e: e.x)
    assert moving.x == moving.y > 100, "both wheels forward, |1.1·v|"
    assert max(e.values[1] for e in b) > 90, "the B record's encoders move too"
    assert c[0].values == (42, 100, 8000, 40, 0, 0, 0, 0, 0), "{4:v} is taken and ignored"
    assert b"##${C42:" in sent, "this firmware's reply before its C record"
    notes = [n.text for n in board.take_notes()]
    assert any("balance_kp = 42" in n for n in notes)
    assert any("not settable" in n for n in notes)
    assert any("saved [42, 100, 8000, 40, 0, 0, 0, 0, 0]" in n for n in notes)


def test_a_data_profile_board_keeps_no_flash_file_and_says_it_has_no_physics(
    tmp_path: Path,
) -> None:
    with pytest.raises(AppmodeError, match="keeps what it saves in memory"):
        profile_named("balance").check(drive=False, flash=True)
    done = run("board", "--profile", "balance", "--flash", str(tmp_path / "f.json"))
    assert done.returncode == 2 and "leave out the flash file" in done.stderr
    assert not (tmp_path / "f.json").exists()


def test_user_values_and_frame_integers_are_exact() -> None:
    kp = load("balance").params[0]
    assert param_values.from_user(kp, "0.42") == 42
    assert param_values.to_user(kp, 42) == "0.42" and param_values.to_user(kp, 30000) == "300"
    for bad, why in [
        ("0.425", "steps of 0.01"),
        ("1e999999999", "a number in 0–21474836.47"),
        ("-1", "a number"),
        ("nan", "a number"),
        ("1_0", "a number"),
    ]:
        with pytest.raises(AppmodeError, match=why):
            param_values.from_user(kp, bad)


def test_params_of_the_balance_car_by_name_in_its_units(tmp_path: Path) -> None:
    record = tmp_path / "s.transcript"
    url = "sim://?profile=balance"
    done = run("params", url, "--set", "balance_kp=0.42", "--json", "--record", str(record))
    assert done.returncode == 0, done.stderr
    assert "set balance_kp = 0.42 (verified)" in done.stderr
    values = json.loads(done.stdout)
    assert values["balance_kp"] == 0.42 and values["velocity_ki"] == 0.4
    sent = [e.text for e in read_transcript(record).entries if e.direction == ">"]
    assert "{0:42}" in sent
    shown = run("params", url)
    assert " 0  balance_kp                300  0–21474836.47      300" in shown.stdout
    wrong = run("params", url, "--set", "balance_kp=0.425")
    assert wrong.returncode == 2
    assert wrong.stderr.strip().endswith("balance_kp takes steps of 0.01 in 0–21474836.47")
    assert len(wrong.stderr.strip().splitlines()) == 1


def test_a_user_s_own_profile_file_works_end_to_end(tmp_path: Path) -> None:
    """A file of one's own: the board serves it, params, monitor and decode name it."""
    own = tmp_path / "rover.toml"
    own.write_text(
        'name = "rover"\n'
        'description = "a rover of my own"\n'
        'source = "my firmware\'s APP_Show"\n'
        'like = "balance"\n'
        "period_ms = [100, 100]\n"
        "[records]\n"
        "B = [\n"
        '  { name = "left", unit = "count", motion = true },\n'
        '  { name = "right", unit = "count", motion = true },\n'
        "]\n"
        "[[params]]\n"
        'name = "speed"\n'
        "maximum = 1000\n"
        "default = 250\n"
        "[[params]]\n"
        'name = "gain"\n'
        "maximum = 5000\n"
        "default = 150\n"
        "scale = 1000\n"
    )
    assert run("profile", "check", str(own)).returncode == 0
    url = f"sim://?profile={own}"
    done = run("params", url, "--set", "gain=2.5", "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == {"speed": 250, "gain": 2.5}
    mon = run("monitor", url, "--json", "--count", "4")
    rows = [json.loads(line) for line in mon.stdout.splitlines()]
    assert {r["kind"] for r in rows} == {"velocity", "attitude"}
    assert set(next(r for r in rows if r["kind"] == "attitude")) == {
        "t",
        "kind",
        "left",
        "right",
        "raw",
    }
    decoded = run("decode", "--profile", str(own), stdin=b"{B3:4}${C250:2500}$")
    assert [json.loads(line) for line in decoded.stdout.splitlines()] == [
        {"kind": "attitude", "left": 3, "right": 4, "raw": "{B3:4}$"},
        {"kind": "params", "speed": 250, "gain": 2500, "raw": "{C250:2500}$"},
    ]


def test_a_broken_profile_file_is_one_line_on_any_command(tmp_path: Path) -> None:
    broken = tmp_path / "broken.toml"
    broken.write_text('name = "x"\nbaud = "fast"\n')
    done = run("monitor", "sim://", "--profile", str(broken))
    assert done.returncode == 2
    errors = [line for line in done.stderr.splitlines() if "error:" in line]
    assert len(errors) == 1 and "Traceback" not in done.stderr  # after the usage, one line
    assert "baud = 'fast'" in errors[0] and "[[params]] is missing" in errors[0]


def test_conform_runs_the_balance_suite_on_its_simulated_board() -> None:
    done = run("conform", "--profile", "balance")
    assert done.returncode == 0, done.stdout
    assert "4 passed, 0 failed against the embedded simulated board (balance profile)" in (
        done.stdout
    )


def test_a_profile_without_a_control_port_refuses_uart2() -> None:
    for args in (
        ["params", "sim://", "--profile", "balance", "--uart2"],
        ["send", "sim://", "--profile", "balance", "--uart2", "Z"],
        ["drive", "--profile", "balance", "--uart2"],
    ):
        done = run(*args, stdin=b"quit\n")
        assert done.returncode == 2, args
        assert done.stderr.strip() == (
            "appmode: error: the balance profile has no control port (UART2): drive its "
            "APP port (leave out --uart2)"
        )


def test_a_firmware_s_own_speed_letters_and_page_names(tmp_path: Path) -> None:
    """Issue 53: a line-following variant whose `K` is a steering page and whose `X`, `Y`
    change the speed by ±100: the speed keys send those letters (and the car goes on in
    the direction in force, as the view says), the page is named as the file names it."""
    own = tmp_path / "follower.toml"
    own.write_text(
        'name = "follower"\ndescription = "a line follower"\nsource = "its APP_Show"\n'
        'like = "balance"\n[pages]\nJ = "joystick"\nK = "steering"\n'
        "[speed_keys]\nX = 100\nY = -100\n"
    )
    record = tmp_path / "s.transcript"
    script = b"drive A\nwait 0.8\nspeed +100\nwait 0.8\nstatus\npage button\nstatus\nquit\n"
    done = run("drive", f"sim://?profile={own}", "--record", str(record), stdin=script)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "sent X: this firmware's speed +100" in out
    after_x = out.split("sent X", 1)[1]
    assert "in force  A forward" in after_x, "X changed the speed, not the motion"
    assert "(K steering)" in out
    entries = read_transcript(record).entries
    speeds = [
        int(e.text[2:].split(":")[0])
        for e in entries
        if e.direction == "<" and e.text.startswith("{A")
    ]
    assert max(speeds) > 200, "twice the data board's speed after X, ×1.1"
    assert [e.text for e in entries if e.direction == ">"][-1] == "Z"
