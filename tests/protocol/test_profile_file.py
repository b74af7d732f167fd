"""Profiles as data files: the shipped three, the tables appmode reads from them, the
`profile` command, and a user's broken file said in one line a mistake."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from appmode.board.profiles import load
from appmode.protocol import params
from appmode.protocol.layouts import SCALED, VELOCITY
from appmode.protocol.profile_file import SHIPPED, ProfileError
from tests.support.processes import run


def test_the_codec_s_tables_are_the_shipped_files():
    sheet, minibalance = load("sheet"), load("minibalance")
    assert [p.name for p in params.PARAMS] == [p.name for p in sheet.params]
    assert [(p.minimum, p.maximum) for p in params.PARAMS] == [
        (p.minimum, p.maximum) for p in sheet.params
    ]
    assert params.DEFAULTS == (500, 10000, 20, 0, 10, 10, 10, 0, 0)  # the sheet, §5
    assert [p.default for p in minibalance.params] == [30, 3000, 40, 0, 40, 10, 10, 0, 0]
    assert [p.name for p in minibalance.params] == [p.name for p in sheet.params]  # like
    assert VELOCITY.fields == ("x", "y", "z", "extra") and VELOCITY.motion == (0, 1, 2)
    assert SCALED.fields == ("abs_x", "abs_y", "battery", "extra")
    assert (SCALED.scale, SCALED.signed, SCALED.battery) == (0.7, False, 2)


def test_the_balance_car_is_its_firmware_s_fields_and_scaled_gains():
    balance = load("balance")
    assert [f.name for f in balance.a] == ["encoder_right", "encoder_left", "battery", "angle"]
    assert balance.a[0].wrap == 256 and not balance.a[0].signed
    assert [f.name for f in balance.b] == ["angle", "encoder_left", "encoder_right"]
    gains = balance.params[:4]
    assert [p.name for p in gains] == ["balance_kp", "balance_kd", "velocity_kp", "velocity_ki"]
    assert all(p.scale == 100 for p in gains)
    assert [p.default for p in gains] == [30000, 100, 8000, 40]
    assert balance.replies == ("##$",) and not balance.control_port and balance.saves


def test_profile_list_and_show_say_what_each_firmware_sends():
    listed = run("profile", "list")
    assert listed.returncode == 0
    assert [line.split()[0] for line in listed.stdout.splitlines()] == list(SHIPPED)
    shown = run("profile", "show", "balance")
    assert shown.returncode == 0, shown.stderr
    assert "balance_kp 0.42 is {0:42}" in shown.stdout
    row = next(line for line in shown.stdout.splitlines() if "velocity_ki" in line)
    assert row.split()[1:4] == ["velocity_ki", "0–21474836.47", "0.4"], row
    assert "no control port" in shown.stdout and "also sends ##$" in shown.stdout
    toml = run("profile", "show", "minibalance", "--toml")
    shipped = Path(__file__).parents[2] / "appmode" / "protocol" / "profiles" / "minibalance.toml"
    assert toml.stdout == shipped.read_text(encoding="utf-8")


def test_a_user_s_file_is_checked_and_read_like_a_shipped_one(tmp_path: Path):
    mine = tmp_path / "mine.toml"
    mine.write_text(
        'name = "mine"\ndescription = "my car"\nsource = "its show.c"\nlike = "sheet"\n'
        '[records]\nA = [{ name = "left", unit = "count", motion = true },'
        ' { name = "right", unit = "count", motion = true },'
        ' { name = "battery", unit = "%", battery = true }, { name = "angle", unit = "°" }]\n'
    )
    done = run("profile", "check", str(mine))
    assert done.returncode == 0 and done.stdout.endswith(": fine\n"), done.stdout + done.stderr
    profile = load(str(mine))
    assert [f.name for f in profile.a] == ["left", "right", "battery", "angle"]
    assert profile.params == load("sheet").params and profile.b == load("sheet").b


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ('name = "x"\nperiod_ms = [50\n', "not TOML: "),
        ('name = "X Y"\n', "name = 'X Y': lower-case letters"),
        ('name = "x"\nlike = "nope"\n', "like = 'nope': name a shipped profile"),
        (
            'name = "x"\nlike = "sheet"\n[records]\nA = [{ name = "a" }]\n',
            "records.A has 1 fields: an A record has 4",
        ),
        (
            'name = "x"\nlike = "sheet"\n[[params]]\nname = "p"\nmaximum = 10\ndefault = 11\n',
            "params[0]: default = 11: a whole number in 0–10",
        ),
        ('name = "x"\nlike = "sheet"\ncolour = "red"\n', "unknown key 'colour'"),
        (
            'name = "x"\nlike = "sheet"\n[records]\nA = [{ name = "a" }, { name = "b" },'
            ' { name = "c", battery = true }, { name = "d" }]\n',
            "records.A: no field says motion = true",
        ),
        ('name = "x"\nboot = ' + "[" * 20_000 + "]" * 20_000 + "\n", "nested too deeply"),
        ('name = "x"\nboot = ' + "{a=" * 5_000 + "1" + "}" * 5_000 + "\n", "nested too deeply"),
        (
            'name = "x"\nlike = "sheet"\n[[params]]\nname = "max_speed"\nmaximum = 9\n'
            "scale = inf\n",
            "params[0]: scale = inf: a number from 1e-06 to 1e+06",
        ),
        (
            'name = "x"\nlike = "sheet"\n[[params]]\nname = "max_speed"\nmaximum = 9\n'
            "scale = 1e-320\n",
            "params[0]: scale = 1e-320: a number from",
        ),
        (
            'name = "x"\nlike = "sheet"\n[records]\nB = [{ name = "a", scale = nan }]\n',
            "records.B[0]: scale = nan",
        ),
        (
            'name = "x"\nlike = "sheet"\ndescription = "\\u001b]52;c;aGk=\\u0007\\u001b[2J"\n',
            "description = '\\x1b]52;c;aGk=\\x07\\x1b[2J': a line of at most 200",
        ),
        (
            'name = "x"\nlike = "sheet"\n[pages]\nK = "\\u001b[8mhidden"\n',
            "[pages]: a capital letter = a page's name",
        ),
        (
            'name = "x"\nlike = "sheet"\n[records]\nB = [{ name = "a", label = "\\u009b2J" }]\n',
            "records.B[0]: label and unit are texts of a line",
        ),
    ],
)
def test_a_broken_profile_is_one_line_a_mistake(tmp_path: Path, text: str, said: str):
    path = tmp_path / "broken.toml"
    path.write_text(text)
    with pytest.raises(ProfileError) as caught:
        load(str(path))
    assert any(said in problem for problem in caught.value.problems), caught.value.problems
    done = run("profile", "check", str(path))
    assert done.returncode == 2 and done.stdout == ""
    lines = done.stderr.splitlines()
    assert lines and all(line.startswith(f"{path}: ") for line in lines), done.stderr
    assert "Traceback" not in done.stderr and any(said in line for line in lines)


def test_a_missing_file_a_fifo_and_a_huge_file_are_one_line_each(tmp_path: Path):
    fifo, huge = tmp_path / "fifo.toml", tmp_path / "huge.toml"
    os.mkfifo(fifo)  # nobody writes it: reading it would wait for ever
    huge.write_bytes(b"#" * 1_000_000 + b"\n")
    cases = (
        (tmp_path / "nowhere.toml", "no such file"),
        (fifo, "not a regular file"),
        (huge, "over 256 kB"),
    )
    for path, why in cases:
        done = run("profile", "check", str(path), timeout=10)
        assert done.returncode == 2, done.stderr
        assert done.stderr.count("\n") == 1 and f"cannot read it ({why}" in done.stderr
        assert "give a file or one of sheet, minibalance, balance" in done.stderr


def test_the_shipped_profiles_module_is_made_from_the_files() -> None:
    """`protocol.profiles` holds each shipped file's text and TOML as the files now are
    (after editing one: python -m tests.support.shipped_profiles)."""
    from tests.support import shipped_profiles

    assert shipped_profiles.MODULE.read_text(encoding="utf-8") == shipped_profiles.render()
