"""socket:// ports say how many bytes wait (pyserial's said 1, so a host read a byte a
pass and a board's answers queued behind its stream: a parameter read over TCP was
sent again and again), and end gently, so the board reads the final stop."""

from __future__ import annotations

import socket
import time
from pathlib import Path

from appmode.ports.urls import open_link
from tests.support.processes import board_process, run, sent_lines


def test_in_waiting_is_every_byte_waiting() -> None:
    with socket.create_server(("127.0.0.1", 0)) as server:
        port = open_link(f"socket://127.0.0.1:{server.getsockname()[1]}")
        conn, _ = server.accept()
        with conn:
            assert port.in_waiting == 0
            conn.sendall(b"{A0:0:0:0}$" * 10)
            deadline = time.monotonic() + 5
            while port.in_waiting < 110 and time.monotonic() < deadline:
                time.sleep(0.01)
            assert port.in_waiting == 110
            assert port.read(port.in_waiting) == b"{A0:0:0:0}$" * 10
            conn.close()
            time.sleep(0.1)
            assert port.in_waiting == 1  # the end, for read to find
        port.close()


def test_a_drive_over_tcp_reads_its_parameters_once_and_ends_with_z(tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    with board_process("--listen", "0", "--quiet", "--record", str(record)) as board:
        done = run("drive", board.url, stdin=b"drive A\nwait 0.5\nstop\n")
    assert done.returncode == 0, done.stderr
    sent = sent_lines(record)
    assert sent.count("{Q:P}") <= 2, sent  # the first read and its check, not a retry a pass
    assert sent[-2:] == ["Z", "Z"] and "A" in sent
