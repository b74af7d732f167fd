"""The pieces that keep the command line's start-up short (issue 64.13): shipped profiles
read through a cache as Python keeps bytecode, NamedTuple without typing, regular
expressions compiled when first used, and the program importing neither pyserial nor
typing for a command that does not use them."""

from __future__ import annotations

import os
import subprocess
import sys
import typing
from pathlib import Path

import pytest

from appmode.patterns import deferred
from appmode.protocol import profile_file

if typing.TYPE_CHECKING:  # as the modules that use it write it
    from typing import NamedTuple
else:
    from appmode.protocol.tuples import NamedTuple

SHEET = Path(profile_file.__file__).parent / "profiles" / "sheet.toml"


def copy_of_sheet(tmp_path: Path) -> tuple[str, str]:
    text = SHEET.read_text(encoding="utf-8")
    (tmp_path / "sheet.toml").write_text(text, encoding="utf-8")
    return str(tmp_path), text


def test_a_shipped_file_is_read_once_then_from_its_cache(tmp_path: Path) -> None:
    folder, text = copy_of_sheet(tmp_path)
    first = profile_file._read_through(folder, "sheet", text, "sheet (shipped)")
    kept = list((tmp_path / "__pycache__").iterdir())
    assert [p.name for p in kept] == [f"sheet.{sys.implementation.cache_tag}.toml"]
    assert first == profile_file._toml(text, "sheet")
    mtime = kept[0].stat().st_mtime_ns
    again = profile_file._read_through(folder, "sheet", text, "sheet (shipped)")
    assert again == first and kept[0].stat().st_mtime_ns == mtime, "read, not written"


def test_a_cache_of_other_text_is_not_used(tmp_path: Path) -> None:
    folder, text = copy_of_sheet(tmp_path)
    profile_file._read_through(folder, "sheet", text, "sheet (shipped)")
    changed = text.replace("baud = 9600", "baud = 19200", 1)
    data = profile_file._read_through(folder, "sheet", changed, "sheet (shipped)")
    assert data["baud"] == 19200, "the file as it is now, not what the cache kept"
    assert profile_file._read_through(folder, "sheet", changed, "x")["baud"] == 19200


@pytest.mark.parametrize("damage", [b"", b"\x00garbage", b"\xfb\x01\x02"])
def test_a_damaged_cache_is_read_past(tmp_path: Path, damage: bytes) -> None:
    folder, text = copy_of_sheet(tmp_path)
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    (cache / f"sheet.{sys.implementation.cache_tag}.toml").write_bytes(damage)
    assert profile_file._read_through(folder, "sheet", text, "s") == profile_file._toml(text, "s")


def test_a_folder_that_cannot_hold_a_cache_is_read_each_time(tmp_path: Path) -> None:
    """As where nobody may write: the cache's folder cannot be made (here a file holds
    its name, which stops root too)."""
    folder, text = copy_of_sheet(tmp_path)
    (tmp_path / "__pycache__").write_bytes(b"")
    for _ in range(2):
        data = profile_file._read_through(folder, "sheet", text, "s")
        assert data == profile_file._toml(text, "s")
    assert (tmp_path / "__pycache__").read_bytes() == b""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["__pycache__", "sheet.toml"]


def test_a_bad_toml_is_one_error_whichever_way_it_is_read(tmp_path: Path) -> None:
    with pytest.raises(profile_file.ProfileError, match="not TOML"):
        profile_file._read_through(str(tmp_path), "x", "name = ", "x (shipped)")


class Row(NamedTuple):
    """A row."""

    name: str
    size: int = 1
    scale: float = 2.0

    def doubled(self) -> int:
        return 2 * self.size


class TypingRow(typing.NamedTuple):
    name: str
    size: int = 1
    scale: float = 2.0


def test_named_tuple_as_typing_makes_it() -> None:
    row = Row("a")
    assert row == ("a", 1, 2.0) == TypingRow("a")
    assert Row._fields == TypingRow._fields and Row._field_defaults == TypingRow._field_defaults
    assert row._replace(size=3).doubled() == 6 and Row.__doc__ == "A row."
    assert repr(row) == "Row(name='a', size=1, scale=2.0)" and Row.__module__ == __name__
    name, size, scale = row
    assert (name, size, scale) == ("a", 1, 2.0)
    with pytest.raises(TypeError, match="without a default follows"):

        class Bad(NamedTuple):
            first: int = 0
            second: int  # type: ignore[misc]  # what the test is about


def test_a_deferred_pattern_compiles_when_first_used() -> None:
    pattern = deferred(rb"(\{[AB](-?[0-9]+)\})")
    assert "_compiled" not in vars(pattern)
    assert pattern.split(b"x{A1}y") == [b"x", b"{A1}", b"1", b"y"]
    assert pattern.fullmatch(b"{B-2}") is not None and pattern.pattern.startswith(b"(")
    assert "_compiled" in vars(pattern)
    assert deferred("[a-c]+").sub("-", "abcd") == "-d"


@pytest.mark.parametrize(
    "words", [["--help"], ["decode"], ["params", "--help"], ["drive", "--help"]]
)
def test_the_program_imports_only_what_the_command_uses(words: list[str]) -> None:
    """pyserial, typing, tomllib and dataclasses were a third of these commands' start-up;
    none of them uses them (a shipped profile's TOML is read from its cache)."""
    subprocess.run([sys.executable, "-m", "appmode", *words], capture_output=True, check=False)
    loaded = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "appmode", *words],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        check=True,
    )
    modules = {line.rsplit("|", 1)[-1].strip() for line in loaded.stderr.splitlines()}
    heavy = {"serial", "typing", "tomllib", "dataclasses", "shutil", "decimal", "json"}
    assert modules & heavy == set()


def test_a_library_that_imports_appmode_opens_its_urls_with_pyserial() -> None:
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            "import appmode, serial; p = serial.serial_for_url('sim://'); "
            "p.write(b'{Q:P}'); print(type(p).__module__); p.close()",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert done.stdout.strip() == "appmode.ports.sim"


def test_help_keeps_to_the_terminal_width_it_is_given() -> None:
    env = {**os.environ, "COLUMNS": "50"}
    done = subprocess.run(
        [sys.executable, "-m", "appmode", "drive", "--help"],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    assert max(len(line) for line in done.stdout.splitlines() if " $ " not in line) <= 50


def test_a_value_the_cache_cannot_keep_leaves_nothing_behind(tmp_path: Path) -> None:
    """TOML's dates are no marshal value: read each time, no half-written cache left."""
    text = "x = 1979-05-27T07:32:00Z\n"
    for _ in range(2):
        assert profile_file._read_through(str(tmp_path), "t", text, "t")["x"].year == 1979
    assert list((tmp_path / "__pycache__").iterdir()) == []
