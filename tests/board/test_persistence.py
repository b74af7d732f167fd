"""Persistence: a save killed at any moment leaves the old or the new parameters."""

from __future__ import annotations

import random
import signal
import subprocess
import sys
import time
from pathlib import Path

from appmode.board.store import JsonFileStore, open_store
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
    store = open_store(str(path))  # a board taking the file tidies killed saves away
    leftovers = [p.name for p in tmp_path.iterdir() if p.name.startswith(".flash.json.")]
    store.close()
    assert leftovers == []


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
