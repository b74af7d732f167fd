"""Load: a host flooding the board (short versions; bench/run_all.py runs 60 s)."""

from __future__ import annotations

import random
import threading
import time
from pathlib import Path

import serial

from tests.support.processes import board_process


def rss_kib(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError("no VmRSS")


def flood(url: str, seconds: float, make: object) -> int:
    """Write as fast as the port takes; returns how many chunks were written."""
    port = serial.Serial(url, 9600, write_timeout=5)
    count = 0
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        port.write(make(count))  # type: ignore[operator]
        count += 1
    port.close()
    return count


def test_flood_of_valid_commands_is_applied_in_order(tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--no-pace", "--quiet", "--record", str(record)) as board:
        time.sleep(0.5)
        before = rss_kib(board.proc.pid)
        sent = flood(board.url, 3.0, lambda k: b"{7:%d}" % k)
        time.sleep(0.5)
        after = rss_kib(board.proc.pid)
    taken = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " > " in line]
    # as one stream: a frame taken across a stall of over the recorder's HOLD is two lines
    expected = "".join(f"{{7:{k}}}" for k in range(sent))
    assert "".join(taken) == expected, "every command, in order"
    assert sent > 10_000
    assert after - before < 8 * 1024, f"memory grew {after - before} KiB"


def test_paced_flood_is_applied_in_order_at_the_line_rate_in_flat_memory(
    tmp_path: Path,
) -> None:
    """A writer far faster than 9600 bps: the pty holds what the board has not taken yet
    (the writer blocks, as on a real line), and the board's own memory stays flat."""
    record = tmp_path / "board.transcript"
    written = []

    def writer(url: str) -> None:
        port = serial.Serial(url, 9600)
        try:
            for k in range(1_000_000):
                port.write(b"{7:%d}" % (k % 1000))
                written.append(k)
        except (serial.SerialException, OSError):
            pass  # the board went away

    with board_process("--pty", "--quiet", "--record", str(record)) as board:
        time.sleep(0.5)
        before = rss_kib(board.proc.pid)
        threading.Thread(target=writer, args=(board.url,), daemon=True).start()
        time.sleep(4.0)
        after = rss_kib(board.proc.pid)
    lines = [line.split(" ", 2) for line in record.read_text().splitlines() if " > " in line]
    # every byte taken, in order: a frame the board took across a stall of over the
    # recorder's HOLD (a loaded machine) is two lines, and the last may be cut short
    taken = "".join(payload for _, _, payload in lines)
    frames = taken.count("}")
    assert taken == "".join(f"{{7:{k % 1000}}}" for k in range(frames + 1))[: len(taken)]
    # Lines are stamped when the server took the bytes in; the first INPUT_BACKLOG bytes go
    # in at once, so measure from a quarter of the way on.
    start = len(lines) // 4
    span = float(lines[-1][0]) - float(lines[start][0])
    rate = sum(len(payload) for _, _, payload in lines[start + 1 :]) / span
    assert 700 < rate <= 960 * 1.01, f"{rate:.0f} bytes/s applied"
    assert len(written) > frames, "the writer got ahead: the pty holds the rest"
    assert after - before < 8 * 1024


def test_garbage_flood_keeps_the_board_alive_and_flat() -> None:
    rng = random.Random(3)
    with board_process("--pty", "--no-pace", "--quiet") as board:
        time.sleep(0.5)
        before = rss_kib(board.proc.pid)
        flood(board.url, 3.0, lambda k: bytes(rng.randrange(256) for _ in range(512)))
        after = rss_kib(board.proc.pid)
        port = serial.Serial(board.url, 9600, timeout=1)
        port.reset_input_buffer()
        port.write(b"{Q:P}")
        got = b""
        end = time.monotonic() + 3
        while b"{C" not in got and time.monotonic() < end:
            got += port.read(200)
        port.close()
    assert b"{C" in got, "the board still answers"
    assert after - before < 8 * 1024
