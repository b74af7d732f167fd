"""The chassis port against peers nobody here wrote from appmode: the vendor driver's
serial side reading appmode's simulated WHEELTEC board, and appmode's host driving a
simulated STM32 (both in tests/support/wheeltec_peer.py, from the shared file alone)."""

from __future__ import annotations

import os
import tty
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from appmode.ports.choice import choose
from appmode.ports.target import parse_target
from appmode.protocol.twist import Twist
from appmode.session.hold import HoldToDrive
from appmode.session.opener import open_session
from tests.support.processes import board_process, run
from tests.support.wheeltec_peer import Stm32, VendorDriver

BOOT_MS = 1500


def quick_profile(tmp_path: Path, kind: str) -> str:
    """A WHEELTEC profile whose boot takes BOOT_MS (the shipped F1's takes 10 s)."""
    path = tmp_path / f"quick-{kind}.toml"
    path.write_text(
        f'name = "quick_{kind}"\nlike = "wheeltec-{kind}"\n'
        f'[chassis]\nkind = "{kind}"\nboot_ms = {BOOT_MS}\n'
    )
    return str(path)


@contextmanager
def opened(path: str) -> Iterator[int]:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd)
    try:
        yield fd
    finally:
        os.close(fd)


@pytest.mark.parametrize("kind", ["mec", "diff"])
def test_the_vendor_driver_reads_the_simulated_board(tmp_path: Path, kind: str) -> None:
    with board_process("--pty", "--profile", quick_profile(tmp_path, kind)) as board:
        assert board.chassis is not None
        with opened(board.chassis) as fd:
            driver = VendorDriver(fd)
            driver.read_for(0.5)
            assert driver.readings and all(r.flag_stop == 1 for r in driver.readings)
            driver.read_for(BOOT_MS / 1000)
            start = len(driver.readings)
            driver.read_for(2.0)
            rate = (len(driver.readings) - start) / 2.0
            assert 15 <= rate <= 22, f"{rate} status frames a second, not 20"
            assert driver.readings[-1].flag_stop == 0, "Flag_Stop clears after the boot"
            for _ in range(25):  # 2.5 s of commands at 10 Hz
                driver.send(0.3, 0.2, 0.5)
                driver.read_for(0.1)
    assert driver.rejected == 0, "every status frame's tail and XOR are right"
    last = driver.readings[-1]
    assert last.vx == pytest.approx(0.3, abs=0.01)
    assert last.vy == pytest.approx(0.2 if kind == "mec" else 0.0, abs=0.01)
    assert last.wz == pytest.approx(0.5, abs=0.01)
    assert last.gyro[2] == pytest.approx(last.wz, abs=0.01), "the gyro agrees with the turn"
    assert last.accel[2] == pytest.approx(9.8, abs=0.05)
    assert 11.0 < last.volts <= 12.6


@contextmanager
def stm32() -> Iterator[tuple[Stm32, str]]:
    master, slave = os.openpty()
    tty.setraw(slave)
    board = Stm32(master)
    board.start()
    try:
        yield board, os.ttyname(slave)
    finally:
        board.stop()
        os.close(slave)
        os.close(master)


def test_send_drives_a_simulated_stm32_and_ends_with_a_zero_frame() -> None:
    with stm32() as (board, port):
        done = run("send", port, "--chassis", "velocity:0.3,0,0.5", "wait:1", "--listen", "0")
    assert done.returncode == 0, done.stderr
    assert "sent again every 0.1 s" in done.stderr
    moving = [t for t in board.taken if t != (0, 0, 0)]
    assert set(moving) == {(0.3, 0.0, 0.5)}
    assert len(moving) >= 8, f"re-sent while it drives: {len(moving)} frames in 1 s"
    assert board.taken[-1] == (0, 0, 0) and board.dropped == 0
    assert "status +0.30 m/s, +0.00 m/s, +0.50 rad/s" in done.stdout


def test_a_session_ends_with_a_zero_frame_and_senses_the_car() -> None:
    with stm32() as (board, port):
        choice = choose(parse_target(port), chassis=True)
        session = open_session(choice, HoldToDrive())
        try:
            session.start()
            for _ in range(15):
                session.move(Twist(0.2, -0.1, 0.3))
                session.tick()
                session.host.poll(0.1)
            sensed = session.sensed(0.0)
        finally:
            session.close()
    assert sensed and sensed[-1][1] == Twist(0.2, -0.1, 0.3)
    assert board.taken[-1] == (0, 0, 0)
    assert (0.2, -0.1, 0.3) in board.taken


def test_a_stalled_status_shows_as_late_and_the_car_is_still_held_and_stopped() -> None:
    """A board whose status frames stop: the session says how old the last one is, keeps
    sending the velocity in force while it drives, and ends with the zero frame."""
    with stm32() as (board, port):
        choice = choose(parse_target(port), chassis=True)
        session = open_session(choice, HoldToDrive(latched=True))
        try:
            session.start()
            session.press("forward")  # latched: held with no repeats, by the re-sends alone
            for _ in range(5):
                session.tick()
                session.host.poll(0.1)
            board.stalled = True
            taken = len(board.taken)
            for _ in range(15):
                session.tick()
                session.host.poll(0.1)
            rows = " ".join(row.text for row in session.status_rows())
        finally:
            session.close()
    assert "last status frame" in rows and "s ago" in rows, rows
    assert len(board.taken) - taken >= 8, "the velocity in force still sent again"
    assert board.taken[-1] == (0, 0, 0)
