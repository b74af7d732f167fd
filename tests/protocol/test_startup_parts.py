"""The pieces that keep the command line's start-up short (issue 64.13): NamedTuple
without typing, regular expressions compiled when first used, and the program importing
neither pyserial nor typing for a command that does not use them (the shipped profiles
are the package's data as a module: tests/protocol/test_profile_file.py)."""

from __future__ import annotations

import os
import subprocess
import sys
import typing

import pytest

from appmode.patterns import deferred
from appmode.protocol import profile_file

if typing.TYPE_CHECKING:  # as the modules that use it write it
    from typing import NamedTuple
else:
    from appmode.protocol.tuples import NamedTuple


def test_a_bad_toml_is_one_error() -> None:
    with pytest.raises(profile_file.ProfileError, match="not TOML"):
        profile_file.parse("name = ", "x")


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
