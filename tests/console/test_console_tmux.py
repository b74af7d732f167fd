"""The console as a person uses it: in tmux, against `appmode board --pty --record`."""

from __future__ import annotations

import contextlib
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from functools import partial
from pathlib import Path

import pytest

from appmode.protocol import params
from tests.support.processes import (
    ROOT,
    board_process,
    board_state,
    sent_lines,
    timed_sent,
    wait_for,
)

SESSION = "appmode-test"
PREFIX = f"appmode-tests-{os.getpid()}"
TMUX = ["tmux", "-L", f"{PREFIX}-0"]
"""A tmux server of this test process's own: the user's server and its environment, and
another test run's, stay apart. Each test gets a server of its own (tests/console/
conftest.py names it `PREFIX-N`): a server exits with its last session, and a
`new-session` that meets the previous test's server exiting fails ("server exited
unexpectedly"); one kept up between tests instead left its panes' processes unreaped."""


WATCHDOG = """\
import glob, os, subprocess, sys, time
while os.getppid() == int(sys.argv[1]):
    time.sleep(0.5)
folder = os.path.join(os.environ.get("TMUX_TMPDIR", "/tmp"), f"tmux-{os.getuid()}")
for socket in glob.glob(os.path.join(folder, sys.argv[2] + "-*")):
    subprocess.run(["tmux", "-L", os.path.basename(socket), "kill-server"], capture_output=True)
"""
"""`WATCHDOG PID PREFIX` ends the tmux servers named PREFIX-… once their parent, process
PID (the test process), has ended: then it is another's child (PID is given, as the test
may end before the watchdog has started)."""
_watchdogs: list[subprocess.Popen[bytes]] = []


def tmux(*args: str) -> str:
    assert shutil.which("tmux"), "these tests drive the console in tmux: apt-get install tmux"
    if not _watchdogs:
        # a run killed mid-test (SIGKILL: a timeout, a benchmark's load) runs no cleanup;
        # its consoles would run on, retrying their port (a path the next pty reuses)
        _watchdogs.append(
            subprocess.Popen(
                [sys.executable, "-c", WATCHDOG, str(os.getpid()), PREFIX],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,  # outlives a kill of this test's process group
            )
        )
    done = subprocess.run([*TMUX, *args], capture_output=True, text=True, check=False)
    assert done.returncode == 0, f"tmux {args[0]}: {done.stderr.strip()}"
    return done.stdout


def appmode_in_tmux(args: str) -> str:
    """The shell command that runs `appmode ARGS` in a tmux pane with this test's data
    folder (a tmux server keeps the environment it started with: it is given here)."""
    data = shlex.quote(os.environ["XDG_DATA_HOME"])
    return f"cd {ROOT} && exec env XDG_DATA_HOME={data} {sys.executable} -m appmode {args}"


def screen(session: str = SESSION) -> str:
    return tmux("capture-pane", "-t", session, "-p")


def wait_screen(pattern: str, timeout: float = 10.0, session: str = SESSION) -> re.Match[str]:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        match = re.search(pattern, screen(session))
        if match:
            return match
        time.sleep(0.02)
    raise AssertionError(f"{pattern!r} never showed; screen:\n{screen(session)}")


def _alive() -> bool:
    done = subprocess.run([*TMUX, "has-session", "-t", SESSION], capture_output=True, check=False)
    return done.returncode == 0


def forward_speed() -> int:
    return int(wait_screen(r"velocity\s+x\s+-?\d+\s+y\s+(-?\d+)").group(1))


class KeyTyper:
    """Keys typed into SESSION by one tmux control-mode client (`tmux -C`): a key costs a
    line on its stdin, not a new tmux process, so a held key's repeats keep their pace
    on a busy machine."""

    def __init__(self) -> None:
        self.proc = subprocess.Popen(
            [*TMUX, "-C", "attach-session", "-t", SESSION],
            stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            text=True,
        )

    def hold(self, key: str, seconds: float, every: float = 0.03) -> list[float]:
        """Type `key` every `every` s for `seconds`, as a held key repeats: when each was
        typed."""
        assert self.proc.stdin is not None
        typed: list[float] = []
        end = time.monotonic() + seconds
        while not typed or typed[-1] < end:
            self.proc.stdin.write(f"send-keys -t {SESSION} {key}\n")
            self.proc.stdin.flush()
            typed.append(time.monotonic())
            time.sleep(every)
        return typed

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        try:
            self.proc.wait(5)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


@pytest.mark.timing
def test_drive_in_tmux_against_a_pty_board(tmp_path: Path) -> None:
    assert shutil.which("tmux"), "tmux is required (.ci/run installs it)"
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--record", str(record), "--quiet") as board:
        command = appmode_in_tmux(f"drive {board.url}")
        tmux("new-session", "-d", "-s", SESSION, "-x", "140", "-y", "40", command)
        typer = KeyTyper()
        try:
            wait_screen(r"REAL BOARD")
            wait_screen(r"params\s+max_speed 500")
            interrupted = []
            for _ in range(3):
                before = len(timed_sent(record))
                pressed = time.monotonic()
                with ThreadPoolExecutor(1) as pool:  # hold Up for 1.2 s, repeating
                    holding = pool.submit(typer.hold, "Up", 1.2)
                    moving_after = None
                    while moving_after is None and not holding.done():
                        if forward_speed() > 0:
                            moving_after = time.monotonic() - pressed
                        time.sleep(0.02)
                    typed = holding.result()
                released = typed[-1] + 0.03  # when the next repeat would have come
                wait_screen(r"in force\s+Z stop", timeout=2)  # the view shows it
                times = timed_sent(record)[before:]
                if [payload for _, payload in times].count("A") > 1:
                    # the console stopped the car mid-hold: the repeats came late (a busy
                    # machine) and it must stop when they do; the next one is a new press,
                    # which lasts longer (FIRST_TIMEOUT). The release is judged on a hold
                    # the console saw whole: this one is typed again.
                    interrupted.append(times)
                    continue
                # the panel's speed on tmux's screen, read every 0.02 s: 0.48 s once
                # beside six workers on two cores
                assert moving_after is not None and moving_after < 0.6, (
                    moving_after,
                    times[:8],  # what the board took, and when it got the A
                    screen(),
                )
                letters = [payload for _, payload in times]
                stop = letters.index("A") + 1
                assert letters[stop] == "Z", times
                stop_at = board.clock_after + times[stop][0]  # on the board's recording
                # due 0.25 s after it, and tmux's pty in between: 0.503 s beside five
                # other workers on two cores
                assert stop_at - released < 0.6, (stop_at - released, times)
                break
            else:
                raise AssertionError(f"three holds in a row were stopped midway: {interrupted}")
            typer.close()
            tmux("send-keys", "-t", SESSION, ":")
            tmux("send-keys", "-t", SESSION, "set max_speed 800", "Enter")
            wait_screen(r"max_speed = 800 \(verified\)")
            wait_screen(r"params\s+max_speed 800")
            tmux("send-keys", "-t", SESSION, "C-c")
            end = time.monotonic() + 5
            while time.monotonic() < end and _alive():
                time.sleep(0.05)
            assert not _alive(), "Ctrl-C ends the console"
        finally:
            typer.close()
            subprocess.run([*TMUX, "kill-session", "-t", SESSION], capture_output=True, check=False)
    sent = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " > " in line]
    assert "A" in sent and "{0:800}" in sent
    assert sent[-1] == "Z", sent[-5:]


def _drive_forward(args: str, session: str = SESSION) -> int:
    """`appmode drive --latched ARGS` in a new tmux session, driving forward: its pid."""
    command = appmode_in_tmux(f"drive --latched {args}")
    tmux("new-session", "-d", "-s", session, "-x", "140", "-y", "40", command)
    wait_screen(r"params\s+max_speed 500", session=session)
    tmux("send-keys", "-t", session, "w")
    wait_screen(r"in force\s+A forward", session=session)
    return int(tmux("display-message", "-p", "-t", session, "#{pane_pid}").strip())


def test_sigterm_ends_the_console_with_z_last(tmp_path: Path) -> None:
    record = tmp_path / "drive.transcript"
    try:
        pid = _drive_forward(f"--record {record}")
        os.kill(pid, signal.SIGTERM)
        end = time.monotonic() + 5
        while time.monotonic() < end and _alive():
            time.sleep(0.05)
        assert not _alive()
    finally:
        subprocess.run([*TMUX, "kill-session", "-t", SESSION], capture_output=True, check=False)
    sent = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " > " in line]
    assert "A" in sent and sent[-1] == "Z"


def test_sigterm_ends_script_mode_with_z_last(tmp_path: Path) -> None:
    record = tmp_path / "script.transcript"
    proc = subprocess.Popen(
        [sys.executable, "-m", "appmode", "drive", "--record", str(record)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        cwd=ROOT,
    )
    assert proc.stdin is not None and proc.stdout is not None
    proc.stdin.write(b"drive A\n")
    proc.stdin.flush()
    end = time.monotonic() + 10
    while time.monotonic() < end and (not record.exists() or " > A" not in record.read_text()):
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    proc.wait(10)
    sent = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " > " in line]
    assert "A" in sent and sent[-1] == "Z"


def test_closing_the_terminal_ends_the_console_with_the_car_stopped(tmp_path: Path) -> None:
    """tmux kill-session: the console gets SIGHUP, as from a closed terminal window."""
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--record", str(record), "--quiet") as board:
        try:
            pid = _drive_forward(board.url)
        finally:
            tmux("kill-session", "-t", SESSION)
        wait_for(lambda: not Path(f"/proc/{pid}").exists())
        sent = sent_lines(record)
        assert "A" in sent and sent[-1] == "Z", sent[-5:]
        assert board_state(board.url) == ((0, 0, 0), tuple(params.DEFAULTS))


def test_at_80x24_help_waveforms_and_the_message_log(tmp_path: Path) -> None:
    command = f"cd {ROOT} && XDG_DATA_HOME={tmp_path} {sys.executable} -m appmode drive"
    tmux("new-session", "-d", "-s", SESSION, "-x", "80", "-y", "24", command)
    try:
        wait_screen(r"\nparameters read")
        assert "Ctrl-Q quit" in screen()  # the key hints fit
        for speed in range(600, 1200, 100):  # more messages than the log shows
            tmux("send-keys", "-t", SESSION, "-l", "l")
            tmux("send-keys", "-t", SESSION, "-l", "+")
            wait_screen(rf"max_speed = {speed} \(verified\)")
        tmux("send-keys", "-t", SESSION, "PageUp")
        wait_screen(r"── \d+ lines back · PgUp/PgDn scroll")
        assert "parameters read" in screen()  # the oldest message is back in view
        tmux("send-keys", "-t", SESSION, "End")
        wait_screen(r"max_speed = 1100 \(verified\)\s*$")
        tmux("send-keys", "-t", SESSION, "-l", "?")
        help_screen = wait_screen(r"quit\s+stop the car and leave").string
        assert "params            read the nine parameters" in help_screen  # all of it
        tmux("send-keys", "-t", SESSION, "Escape")
        tmux("send-keys", "-t", SESSION, "-l", "v")
        waves = wait_screen(r" vy\s+[▁▂▃▄▅▆▇█]+").string
        assert " battery " in waves and "not saved" not in waves
        assert all(len(line) <= 80 for line in waves.splitlines())
        tmux("send-keys", "-t", SESSION, "C-q")  # max_speed was changed and not saved
        wait_screen(r"not saved: max_speed 500 → 1100 — :save keeps it; quit again to leave")
        assert _alive()
        tmux("send-keys", "-t", SESSION, "C-q")
        wait_for(lambda: not _alive())
    finally:
        if _alive():
            tmux("kill-session", "-t", SESSION)


def _two_signals(tmp_path: Path, pause: float) -> str | None:
    """A console on a board of its own, driving; SIGTERM, then SIGHUP `pause` s later:
    None when the board's last unit is the stop and it is still, else what it was."""
    record = tmp_path / f"board-{pause}.transcript"
    session = f"{SESSION}-{round(pause * 1000)}ms"  # a dot would name a pane
    with board_process("--pty", "--record", str(record), "--quiet") as board:
        try:
            pid = _drive_forward(board.url, session)
            os.kill(pid, signal.SIGTERM)
            time.sleep(pause)
            with contextlib.suppress(ProcessLookupError):  # it may have ended already
                os.kill(pid, signal.SIGHUP)
            wait_for(lambda: not Path(f"/proc/{pid}").exists())
        finally:
            subprocess.run([*TMUX, "kill-session", "-t", session], capture_output=True, check=False)
        sent = sent_lines(record)
        if sent[-1] != "Z":
            return f"SIGHUP {pause} s after SIGTERM: {sent[-5:]}"
        if board_state(board.url) != ((0, 0, 0), tuple(params.DEFAULTS)):
            return f"SIGHUP {pause} s after SIGTERM: the board is not still at its defaults"
    return None


@pytest.mark.slow
def test_two_ending_signals_end_the_console_with_z_last(tmp_path: Path) -> None:
    """Issue 22.2: SIGTERM and SIGHUP together. The console used to give the signals
    back to their default action before its final `Z`: a SIGHUP then killed it. The
    second signal at several points of the ending, each console on a board of its own,
    all at once (they mostly wait)."""
    pauses = (0, 0.01, 0.02, 0.04, 0.08, 0.12)
    with ThreadPoolExecutor(len(pauses)) as pool:
        failures = [why for why in pool.map(partial(_two_signals, tmp_path), pauses) if why]
    assert not failures, failures


def test_the_console_keeps_its_history_in_the_tests_folder_whatever_tmux_holds(
    tmp_path: Path,
) -> None:
    """Issue 22.16: a tmux server started elsewhere keeps its own XDG_DATA_HOME; the
    console started in it must still write this test's data folder, not the user's."""
    decoy = tmp_path / "decoy"
    subprocess.run(  # the server starts with the decoy folder in its environment
        [*TMUX, "new-session", "-d", "-s", "decoy", "sleep 30"],
        env={**os.environ, "XDG_DATA_HOME": str(decoy)},
        check=True,
    )
    try:
        tmux("new-session", "-d", "-s", SESSION, "-x", "140", "-y", "40", appmode_in_tmux("drive"))
        wait_screen(r"parameters read", timeout=30)  # the first read is over: not busy
        tmux("send-keys", "-t", SESSION, ":")
        tmux("send-keys", "-t", SESSION, "-l", "speed 600")
        wait_screen(r"(?m)^:speed 600", timeout=30)  # typed into the command line
        tmux("send-keys", "-t", SESSION, "Enter")
        wait_screen(r"max_speed 600", timeout=30)
        tmux("send-keys", "-t", SESSION, "C-q")
        tmux("send-keys", "-t", SESSION, "C-q")
        wait_for(lambda: not _alive())
    finally:
        for name in (SESSION, "decoy"):
            subprocess.run([*TMUX, "kill-session", "-t", name], capture_output=True, check=False)
    history = Path(os.environ["XDG_DATA_HOME"]) / "appmode" / "history"
    assert "speed 600" in history.read_text()
    assert not decoy.exists()


def test_messages_wrap_between_words() -> None:
    """Issue 23.3: a message longer than the screen was cut inside a word (`th at`)."""
    tmux("new-session", "-d", "-s", SESSION, "-x", "60", "-y", "20", appmode_in_tmux("drive"))
    try:
        wait_screen(r"parameters read")
        tmux("send-keys", "-t", SESSION, ":", "set max_speed 70000000", "Enter")
        wait_screen(r"error: max_speed \(parameter 0\) must be in 0–65535, not\n  70000000")
    finally:
        tmux("kill-session", "-t", SESSION)


def test_a_test_process_killed_outright_leaves_no_console_behind() -> None:
    """A test process that is SIGKILLed (no cleanup runs) has its tmux server, and the
    consoles in it, ended by the watchdog within a second or so."""
    code = (
        "import sys, time\n"
        "from tests.console import test_console_tmux as t\n"
        "t.tmux('new-session', '-d', '-s', 'orphan', 'sleep 60')\n"
        "print(t.TMUX[2], flush=True)\n"
        "time.sleep(60)\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.PIPE, text=True
    )
    try:
        assert child.stdout is not None
        server = ["tmux", "-L", child.stdout.readline().strip()]
        alive = [*server, "has-session", "-t", "orphan"]
        assert subprocess.run(alive, capture_output=True, check=False).returncode == 0
    finally:
        child.kill()
        child.wait()
    end = time.monotonic() + 10
    while subprocess.run(alive, capture_output=True, check=False).returncode == 0:
        assert time.monotonic() < end, "the killed test's tmux session still runs"
        time.sleep(0.1)


def test_the_viewers_server_never_writes_over_the_console() -> None:
    """Issue 78.5: 20 malformed messages and a viewer killed mid-connection: the SDK's
    complaints are the session's messages, one of a kind, and the screen stays whole."""
    pytest.importorskip("foxglove", reason="the foxglove extra is not installed")
    import asyncio
    import socket

    from tests.support.foxglove_client import malformed

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]

    with board_process() as board:
        command = appmode_in_tmux(f"drive {board.url} --foxglove {port} --foxglove-drive")
        tmux("new-session", "-d", "-s", SESSION, "-x", "140", "-y", "40", command)
        try:
            wait_screen(r"params\s+max_speed")
            asyncio.run(malformed(f"ws://127.0.0.1:{port}"))
            wait_screen(r"foxglove: Error receiving from client")
            time.sleep(1.0)
            lines = screen().splitlines()
            assert lines[0].startswith(" appmode drive"), lines[:3]  # the frame is whole
            assert any("q H ↖ front-left" in line for line in lines)
            server = [line for line in lines if re.search("Invalid message|Error receiving", line)]
            assert len(server) == 2 and all(line.startswith("foxglove: ") for line in server)
            assert sum("a /cmd_vel message was ignored" in line for line in lines) == 1
            tmux("send-keys", "-t", SESSION, "C-q")
        finally:
            subprocess.run([*TMUX, "kill-session", "-t", SESSION], capture_output=True, check=False)
