"""Issue 49.14: the smaller findings, each as the tester met it."""

from __future__ import annotations

import io
import os
import re
from contextlib import redirect_stderr
from pathlib import Path

import pytest

from appmode.ports.endpoints import parse_listen
from appmode.transcript.replay import _progress
from tests.support.processes import board_process, run
from tests.support.web import web_process


@pytest.mark.parametrize(
    ("given", "bound"),
    [("127.1:0", "127.0.0.1"), ("0x7f000001:80", "127.0.0.1"), ("0:0", "0.0.0.0")],
)
def test_short_ipv4_forms_are_the_addresses_they_bind(given: str, bound: str) -> None:
    assert parse_listen(given)[0] == bound
    assert parse_listen("localhost:1")[0] == "localhost"


def test_listen_0_is_every_address_and_is_served_as_such(tmp_path: Path) -> None:
    with web_process(tmp_path, "--listen", "0:0") as web:
        assert web.address.startswith("https://"), web.address
        _, err = web.stop()
    assert "WARNING: the page is served on 0.0.0.0" in err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_as_certificate_is_one_line_not_a_hang(tmp_path: Path) -> None:
    fifo = tmp_path / "cert.pem"
    os.mkfifo(fifo)
    done = run("web", "--cert", str(fifo), "--key", str(fifo), timeout=20)
    assert done.returncode == 2
    assert (
        done.stderr == f"appmode: error: cannot serve HTTPS with {fifo}: it is not a file; "
        "give a PEM file\n"
    )


def test_a_kept_certificate_that_is_garbage_is_replaced_saying_so(tmp_path: Path) -> None:
    folder = tmp_path / "data" / "appmode"
    folder.mkdir(parents=True)
    (folder / "web-cert.pem").write_text("not a certificate\n")
    (folder / "web-key.pem").write_text("not a key\n")
    with web_process(tmp_path, "--listen", "0.0.0.0:0") as web:
        _, err = web.stop()
    assert "made a new certificate for the page: the one kept in" in err
    assert "could not be read" in err and "its fingerprint is new" in err


def test_params_save_where_saved_json_cannot_be_written_says_what_was_done(
    tmp_path: Path,
) -> None:
    """The tester's read-only folder, as a file in the folder's place (root writes a
    read-only folder): the set and the save went out, and saved.json is named."""
    (tmp_path / "data").write_text("a file, not a folder\n")
    with board_process("--pty", "-q") as board:
        done = run(
            "params",
            board.url,
            "--set",
            "max_speed=800",
            "--save",
            env={"XDG_DATA_HOME": str(tmp_path / "data")},
        )
    assert done.returncode == 0, done.stderr
    assert "set max_speed = 800 (verified)" in done.stderr
    assert re.search(r"WARNING: cannot write saved parameters \S+saved.json: ", done.stderr)
    assert "--verify-saved will not know this save" in done.stderr


@pytest.mark.parametrize(
    "args", [("replay", "--speed", "١", "--to", "sim://", "x"), ("send", "sim://", "wait:٠.١")]
)
def test_digits_of_other_scripts_are_refused(args: tuple[str, ...]) -> None:
    done = run(*args)
    assert done.returncode == 2
    assert "not a number" in done.stderr or "wait takes seconds" in done.stderr


def test_the_replay_progress_line_fits_80_columns() -> None:
    shown = io.StringIO()
    with redirect_stderr(shown):
        _progress("/some/long/folder/" + "n" * 90 + ".transcript")(1234.5, 99999.9)
        _progress("short.transcript")(1.0, 2.0)
    for line in shown.getvalue().split("\r\033[K")[1:]:
        assert len(line) <= 79, line


def test_dump_refuses_the_range_conform_refuses(tmp_path: Path) -> None:
    """`dump` passed `{A0:5..1:0:0}$`, which `conform` rejected: one check for both now."""
    bad = tmp_path / "bad.transcript"
    bad.write_text("# appmode transcript v1\n0.500 < {A0:5..1:0:0}$\n")
    said = f"appmode: error: {bad}:2: 5..1: a field LO..HI needs LO <= HI\n"
    for command in ("dump", "conform"):
        done = run(command, str(bad))
        assert (done.returncode, done.stderr) == (2, said), command
