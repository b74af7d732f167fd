"""Start real appmode processes for end-to-end tests, and always stop them."""

from __future__ import annotations

import os
import selectors
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from appmode.testing.process import BoardProcess
from appmode.testing.process import board_process as appmode_board_process

ROOT = Path(__file__).resolve().parents[2]


def appmode_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "appmode", *args]


def run(
    *args: str,
    timeout: float = 60,
    stdin: bytes = b"",
    limits: Callable[[], None] | None = None,
    env: dict[str, str] | None = None,
) -> subprocess.CompletedProcess[str]:
    """`appmode ARGS` run to its end; `limits` runs in the child first (resource limits);
    `env` is added to the environment."""
    done = subprocess.run(
        appmode_cmd(*args),
        input=stdin.decode(),
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=ROOT,
        check=False,
        preexec_fn=limits,
        env=None if env is None else {**os.environ, **env},
    )
    return done


def serving(
    *args: str, data: Path, env: dict[str, str] | None = None
) -> tuple[subprocess.Popen[str], str]:
    """`appmode ARGS` started (its data folder in `data`, `env` added), and the first line
    it printed within 45 s, "" if none (beside a second suite, load 8 on two cores, a
    start took over 20 s)."""
    proc = subprocess.Popen(
        appmode_cmd(*args),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
        env={**os.environ, "XDG_DATA_HOME": str(data), **(env or {})},
    )
    assert proc.stdout is not None
    selector = selectors.DefaultSelector()
    selector.register(proc.stdout, selectors.EVENT_READ)
    return proc, proc.stdout.readline() if selector.select(45) else ""


def scripted(url: str, script: str) -> subprocess.Popen[str]:
    """`appmode drive URL` in script mode, `script` given on its standard input (which
    stays open: the session runs on after the script's last line)."""
    proc = subprocess.Popen(
        appmode_cmd("drive", url),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    assert proc.stdin is not None
    proc.stdin.write(script)
    proc.stdin.flush()
    return proc


def stop_process(proc: subprocess.Popen[str], sig: int = signal.SIGTERM) -> str:
    """Send `sig` to a process still running, wait for its end (kill it after 10 s);
    return its stderr."""
    if proc.poll() is None:
        proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
    return err


@contextmanager
def board_process(*args: str) -> Iterator[BoardProcess]:
    with appmode_board_process(*args, cwd=ROOT) as board:
        yield board


def wait_for(predicate: object, timeout: float = 10.0) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():  # type: ignore[operator]
            return
        time.sleep(0.05)
    raise AssertionError("condition not met in time")


def board_state(url: str, seconds: float = 1.5) -> tuple[tuple[int, int, int], tuple[int, ...]]:
    """What a served board is doing now, read from its own telemetry as a new client:
    the last velocity (x, y, z) after `seconds` (long enough for a stopped car's speed
    to decay to 0) and its parameters (`{Q:P}`, which changes no motion)."""
    import serial

    from appmode.protocol.app import ParamsRecord, Velocity
    from appmode.protocol.app_decoders import BoardDecoder

    decoder = BoardDecoder()
    velocity: tuple[int, int, int] | None = None
    values: tuple[int, ...] = ()
    with serial.serial_for_url(url, baudrate=9600, timeout=0.05) as port:
        port.write(b"{Q:P}")
        end = time.monotonic() + seconds
        while time.monotonic() < end or velocity is None or not values:
            assert time.monotonic() < end + 5, "the board sent no telemetry"
            for event in decoder.feed(port.read(256)):
                if isinstance(event, Velocity):
                    velocity = (event.x, event.y, event.z)
                elif isinstance(event, ParamsRecord):
                    values = event.values
    return velocity, values


def sent_lines(record: Path) -> list[str]:
    """The `>` payloads of a transcript, in order."""
    return [payload for _, payload in timed_sent(record)]


def timed_sent(record: Path) -> list[tuple[float, str]]:
    """The `>` lines of a transcript: (its time, on the board's clock; the payload)."""
    units = (line.split(" ", 2) for line in record.read_text().splitlines() if " > " in line)
    return [(float(when), payload) for when, _, payload in units]
