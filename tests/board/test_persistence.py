"""Persistence: a save killed at any moment leaves the old or the new parameters."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import serial

import appmode.ports.urls  # noqa: F401 - registers sim://
from appmode.board.store import JsonFileStore, open_store
from appmode.errors import AppmodeError
from appmode.protocol import params
from tests.support.processes import ROOT

SAVER = """
import sys
from appmode.protocol import params
from appmode.board.store import JsonFileStore
store = JsonFileStore(sys.argv[1])
a = list(params.DEFAULTS)
b = [v + 1 for v in params.DEFAULTS]
print("ready", flush=True)
while True:
    store.save(a)
    store.save(b)
"""


def test_a_save_killed_midway_leaves_old_or_new_never_broken(tmp_path: Path) -> None:
    path = tmp_path / "flash.json"
    JsonFileStore(path).save(params.DEFAULTS)
    expected = {params.DEFAULTS, tuple(v + 1 for v in params.DEFAULTS)}
    rng = random.Random(1)
    for _ in range(30):
        proc = subprocess.Popen(
            [sys.executable, "-c", SAVER, str(path)], cwd=ROOT, stdout=subprocess.PIPE
        )
        assert proc.stdout is not None
        proc.stdout.readline()
        time.sleep(rng.uniform(0.0, 0.05))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        values, warning = JsonFileStore(path).load()
        assert warning is None and values in expected
    (tmp_path / ".flash.json.swp").write_bytes(b"an editor's")
    store = open_store(str(path))  # a board taking the file tidies killed saves away
    leftovers = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".flash.json."))
    store.close()
    assert leftovers == [".flash.json.appmode-lock", ".flash.json.swp"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [".flash.json.swp", "flash.json"]


def test_a_second_board_on_the_same_flash_refuses(tmp_path: Path) -> None:
    flash = str(tmp_path / "b.json")
    first = subprocess.Popen(
        [sys.executable, "-m", "appmode", "board", "--pty", "--quiet", "--flash", flash],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert first.stdout is not None and first.stdout.readline().startswith("port: ")
        second = subprocess.run(
            [sys.executable, "-m", "appmode", "board", "--pty", "--flash", flash],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert second.returncode == 2
        assert f"flash file {flash} is in use by another board (pid {first.pid})" in (second.stderr)
        assert second.stderr.count("\n") == 1
    finally:
        first.terminate()
        first.wait(10)
    third = subprocess.Popen(
        [sys.executable, "-m", "appmode", "board", "--pty", "--quiet", "--flash", flash],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert third.stdout is not None and third.stdout.readline().startswith("port: ")
    third.terminate()
    third.wait(10)


def test_a_flash_that_is_not_a_regular_file_is_refused_and_nothing_made_beside_it(
    tmp_path: Path,
) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(AppmodeError, match=f"flash file {fifo} is not a regular file"):
        open_store(str(fifo))
    assert [p.name for p in tmp_path.iterdir()] == ["pipe"]


@pytest.mark.parametrize(
    ("content", "why"),
    [
        (b"[" * 30_000, "nested too deeply"),
        (b'\xff{"format": "appmode-flash"}', "not UTF-8 text"),
        (b" " * 100_000, "too large for a flash file"),
    ],
)
def test_an_odd_flash_file_is_a_warning_naming_it(tmp_path: Path, content: bytes, why: str) -> None:
    path = tmp_path / "flash.json"
    path.write_bytes(content)
    values, warning = JsonFileStore(path).load()
    assert values is None and warning is not None
    assert warning.startswith(f"{path}: ") and why in warning


def test_a_sim_url_that_fails_to_open_does_not_keep_its_flash_locked(tmp_path: Path) -> None:
    flash = tmp_path / "flash.json"
    with pytest.raises(serial.SerialException, match="faults"):
        serial.serial_for_url(f"sim://?flash={flash}&faults=nonsense")
    open_store(str(flash)).close()  # free: nothing holds it
    assert list(tmp_path.iterdir()) == []
