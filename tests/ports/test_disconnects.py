"""Disconnects: boards killed and restarted, ptys that vanish, TCP resets, clients killed."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from appmode.host.app.client import Host
from appmode.host.events import LinkStatus
from appmode.protocol.app import Velocity
from tests.support.processes import (
    ROOT,
    BoardProcess,
    board_process,
    board_state,
    run,
    wait_for,
)


def test_monitor_follows_a_pty_board_that_dies_and_returns(tmp_path: Path) -> None:
    link = str(tmp_path / "board")
    first = BoardProcess("--pty", "--link", link, "--quiet")
    monitor = subprocess.Popen(
        [sys.executable, "-m", "appmode", "monitor", link],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert monitor.stderr is not None and monitor.stdout is not None
    said: list[str] = []  # what it says on stderr, read as it comes
    reader = threading.Thread(target=lambda: said.extend(monitor.stderr), daemon=True)
    reader.start()
    second = None
    try:
        monitor.stdout.readline()  # a record came: it is monitoring
        first.kill()  # the device vanishes: the pty is gone, the link dangles
        wait_for(lambda: any("lost" in line for line in said), timeout=30)
        second = BoardProcess("--pty", "--link", link, "--quiet")
        wait_for(lambda: any("is back" in line for line in said), timeout=30)
        time.sleep(1.0)  # records again
    finally:
        monitor.send_signal(signal.SIGINT)
        out = monitor.stdout.read()  # to its end: the monitor has stopped
        monitor.wait(10)
        reader.join(10)
        if second is not None:
            second.stop()
    err = "".join(said)
    assert "lost" in err and "is back" in err, err
    after_back = out.splitlines()[-5:]
    assert all(" < {" in line for line in after_back), "records again after the return"
    assert "Traceback" not in err


@pytest.mark.slow
def test_console_says_the_link_is_lost_and_drives_again_when_back(tmp_path: Path) -> None:
    """The board dies before `drive A` and comes back before `drive C`. Each step waits
    for what the console says, not for a clock: on a loaded machine the console may
    take seconds to start (issue 22.15)."""
    link = str(tmp_path / "board")
    first = BoardProcess("--pty", "--link", link, "--quiet")
    drive = subprocess.Popen(
        [sys.executable, "-m", "appmode", "drive", link],
        cwd=ROOT,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert drive.stdin is not None and drive.stdout is not None
    said: list[str] = []

    def until(text: str) -> None:
        assert drive.stdout is not None
        while not any(text in line for line in said):
            line = drive.stdout.readline()
            assert line, f"the console ended before saying {text!r}: {said}"
            said.append(line)

    record = tmp_path / "second.transcript"
    second = None
    watchdog = threading.Timer(90, drive.kill)  # a console that says nothing ends the wait
    watchdog.start()
    try:
        drive.stdin.write("wait 2\ndrive A\nwait 4\n")
        drive.stdin.flush()
        until("parameters read")
        first.kill()  # the board dies before `drive A`
        until("link is down: not driving")
        second = BoardProcess("--pty", "--link", link, "--quiet", "--record", str(record))
        until("is back")
        drive.stdin.write("drive C\nwait 0.5\nstatus\n")
        drive.stdin.flush()
        out, _ = drive.communicate(timeout=30)
    finally:
        watchdog.cancel()
        drive.kill()
        if second is not None:
            second.stop()
    text = "".join(said) + out
    assert "lost" in text and "link is down: not driving" in text and "is back" in text
    assert "in force  C right" in text, text
    sent = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " > " in line]
    assert "C" in sent and sent[-1] == "Z" and "A" not in sent


def test_a_tcp_reset_is_reported_and_the_host_resumes() -> None:
    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]
    host = Host(f"socket://127.0.0.1:{port}")
    conn, _ = listener.accept()
    conn.sendall(b"{A1:2:3:0}$")
    events = host.poll(1.0)
    assert events == [Velocity(1, 2, 3, 0)]
    conn.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    conn.close()  # RST
    listener.close()
    statuses: list[LinkStatus] = []
    board = None
    try:
        end = time.monotonic() + 10
        while time.monotonic() < end and not (statuses and statuses[-1].up):
            for event in host.poll(0.2):
                if isinstance(event, LinkStatus):
                    statuses.append(event)
                    if not event.up and board is None:
                        board = BoardProcess("--listen", f"127.0.0.1:{port}", "--quiet")
        assert [s.up for s in statuses] == [False, False, True]  # lost, opens, back
        assert host.read_params()[0] == 500
    finally:
        host.close()
        if board is not None:
            board.stop()


def test_board_keeps_serving_after_clients_are_killed() -> None:
    for where in (("--pty",), ("--listen", "0")):
        with board_process(*where, "--quiet") as board:
            client = subprocess.Popen(
                [sys.executable, "-m", "appmode", "monitor", board.url],
                cwd=ROOT,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
            )
            assert client.stdout is not None
            client.stdout.readline()
            client.kill()  # no goodbye, no Z
            client.wait()
            wait_for(lambda: board.proc.poll() is None)
            with Host(board.url) as host:
                assert host.read_params()[0] == 500
            assert board.proc.poll() is None


def test_a_board_survives_an_app_client_reset_while_uart2_data_arrives() -> None:
    """A client that resets (SO_LINGER 0) while the other port's bytes arrive: the write
    to the gone client and its pending read come in one pass of the server (issue 22.5)."""
    with board_process("--listen", "127.0.0.1:0", "--listen2", "127.0.0.1:0", "--quiet") as b:
        app_host, app_port = b.url.removeprefix("socket://").rsplit(":", 1)
        uart2_host, uart2_port = b.uart2.removeprefix("socket://").rsplit(":", 1)
        uart2 = socket.create_connection((uart2_host, int(uart2_port)))
        try:
            for _ in range(8):
                app = socket.create_connection((app_host, int(app_port)))
                app.sendall(b"JA")
                time.sleep(0.05)  # records are on their way to it
                app.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                uart2.sendall(bytes.fromhex("FF FE 80 80 11 00 00 00 00 00") * 20)
                app.close()  # RST
                uart2.sendall(bytes.fromhex("FF FE 80 80 11 00 00 00 00 00") * 20)
                time.sleep(0.05)
            assert b.proc.poll() is None, b.stop()
            _, values = board_state(b.url)
            assert len(values) == 9
        finally:
            uart2.close()
        err = b.stop()
    assert "Traceback" not in err and "AssertionError" not in err


def test_links_name_both_ports_and_one_left_by_a_crash_reaches_no_terminal(
    tmp_path: Path,
) -> None:
    """Issue 69.2 and 69.5: `--link car` names both ports (`car`, `car.uart2`), each
    reaching the device its line names; a link left by a board that crashed leads to no
    port at all (issue 23.6: not to the pty number another program, or another board's
    control port, took since) and says so."""
    link = tmp_path / "car"
    board = BoardProcess("--pty", "--link", str(link), "--quiet")
    assert os.path.realpath(link) == board.url and os.readlink(link) != board.url
    assert os.path.realpath(f"{link}.uart2") == board.uart2
    done = run("send", f"{link}.uart2", "--uart2", "stop")
    assert done.returncode == 0, done.stderr
    board.kill()  # no clean-up: the links stay
    done = run("monitor", str(link), "--count", "1")
    assert done.returncode == 2, done.stderr
    assert f"no such port {link}: it is a link to /proc/" in done.stderr, done.stderr
    assert "the pseudo-terminal of a board that has stopped" in done.stderr
    clean = BoardProcess("--pty", "--link", str(tmp_path / "other"), "--quiet")
    clean.stop()
    assert not (tmp_path / "other").is_symlink() and not (tmp_path / "other.uart2").is_symlink()


def test_a_shell_s_terminal_is_not_taken_for_a_board(tmp_path: Path) -> None:
    """Issue 69.2: the README's UART2 example wrote to /dev/pts/1, on that machine
    someone's terminal. A pty that is a program's terminal is refused in a line."""
    if shutil.which("tmux") is None:
        pytest.fail("tmux is needed for a shell's terminal (apt-get install tmux)")
    server = ["tmux", "-L", f"appmode-terminal-{os.getpid()}"]
    subprocess.run([*server, "new-session", "-d", "-s", "t", "bash --norc"], check=True)
    try:
        tty = subprocess.run([*server, "display", "-p", "-t", "t", "#{pane_tty}"],
                             capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
        wait_for(lambda: b"bash" in subprocess.run(["ps", "-t", tty], capture_output=True).stdout)
        for command in (("send", tty, "--uart2", "stop"), ("params", tty)):
            done = run(*command)
            assert done.returncode == 2, done.stderr
            assert f"{tty} is not a board: it is the terminal of bash" in done.stderr
            assert done.stderr.count("\n") == 1
    finally:
        subprocess.run([*server, "kill-server"], capture_output=True, check=False)
