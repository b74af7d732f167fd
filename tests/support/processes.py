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


class BoardProcess:
    """`appmode board ...` running; `url` is what it printed after 'port: ', `uart2`
    after 'uart2: '."""

    def __init__(self, *args: str) -> None:
        self.proc = subprocess.Popen(
            appmode_cmd("board", *args),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        self.url = self._read_port_line()
        self.clock_after = time.monotonic()
        """At or after the board's clock zero (it printed the port line after it): a time
        of its recording, t, happened at or before `clock_after + t` on this machine's
        monotonic clock."""
        self.uart2 = self._read_uart2_line()
        self.details: dict[str, str] = {}
        """With --bluetooth: the stand-in's `bus`, `ble` and `spp` lines; with
        --advertise: the `ble` and `spp` lines."""
        lines = 3 if "--bluetooth" in args else 2 if "--advertise" in args else 0
        if lines:
            assert self.proc.stdout is not None
            for _ in range(lines):
                name, _, value = self.proc.stdout.readline().strip().partition(": ")
                self.details[name] = value

    def _read_port_line(self, timeout: float = 20.0) -> str:
        assert self.proc.stdout is not None
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        if not sel.select(timeout):
            self.stop()
            raise AssertionError(f"board printed no port line in {timeout} s")
        first = self.proc.stdout.readline()
        if not first.startswith("port: "):
            err = self.stop()
            raise AssertionError(f"board said {first!r}; stderr: {err}")
        return first[len("port: ") :].strip()

    def _read_uart2_line(self) -> str:
        """The control port's line, printed right after the port line."""
        assert self.proc.stdout is not None
        second = self.proc.stdout.readline()
        if not second.startswith("uart2: "):
            err = self.stop()
            raise AssertionError(f"board said {second!r} after its port line; stderr: {err}")
        return second[len("uart2: ") :].strip()

    def stop(self, sig: int = signal.SIGTERM) -> str:
        """Stop it (SIGTERM by default); return its stderr."""
        return stop_process(self.proc, sig)

    def kill(self) -> None:
        self.proc.kill()
        self.proc.communicate()


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
    board = BoardProcess(*args)
    try:
        yield board
    finally:
        board.stop()


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
