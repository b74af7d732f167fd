"""A simulated board served by an `appmode board` process, for tests and benchmarks
that want it in a process of its own (`served.ServedBoard` serves one in a thread of
the caller's): started with the command line's options, its ports read from what it
prints, stopped with a signal."""

from __future__ import annotations

import selectors
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from appmode.board.profiles import profile_named


class BoardProcess:
    """`appmode board ARGS` running. `url` and `uart2` are the first board's ports (what
    it printed after `port: ` and `uart2: `), `chassis` its chassis port (a WHEELTEC
    profile's, else None), `urls` every board's APP port (`--count`),
    `details` what `--bluetooth` (`bus`, `ble`, `spp`) or `--advertise` (`ble`, `spp`)
    printed after them."""

    def __init__(self, *args: str, cwd: str | Path | None = None, start: float = 20.0) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "appmode", "board", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=cwd,
        )
        self.urls: list[str] = []
        self.uart2s: list[str] = []
        self.chassis: str | None = None
        self._started(start)
        count = int(args[args.index("--count") + 1]) if "--count" in args else 1
        profile = args[args.index("--profile") + 1] if "--profile" in args else "sheet"
        for _ in range(count):
            self.urls.append(self._line("port: "))
            self.clock_after = time.monotonic()
            """At or after the board's clock zero (it printed its port line after it): a
            time of its recording, t, happened at or before `clock_after + t`."""
            self.uart2s.append(self._line("uart2: "))
            if profile_named(profile).chassis is not None:
                chassis = self._line("chassis: ")
                self.chassis = self.chassis or chassis
        self.url, self.uart2 = self.urls[0], self.uart2s[0]
        self.details: dict[str, str] = {}
        lines = 3 if "--bluetooth" in args else 2 if "--advertise" in args else 0
        for _ in range(lines):
            name, _, value = self._line("").partition(": ")
            self.details[name] = value

    def _started(self, timeout: float) -> None:
        """Wait for its first line (AssertionError after `timeout` seconds): the lines
        after it follow at once."""
        assert self.proc.stdout is not None
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        if not sel.select(timeout):
            self.stop()
            raise AssertionError(f"appmode board printed nothing in {timeout} s")

    def _line(self, prefix: str) -> str:
        """The next line it prints, after `prefix`; AssertionError (its stderr) if it
        prints another."""
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        if not line.startswith(prefix):
            err = self.stop()
            raise AssertionError(f"appmode board said {line!r}, not {prefix!r}; stderr: {err}")
        return line[len(prefix) :].strip()

    def stop(self, sig: int = signal.SIGTERM) -> str:
        """Stop it (SIGTERM by default, SIGKILL after 10 s); its stderr."""
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            _, err = self.proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            _, err = self.proc.communicate()
        return err

    def kill(self) -> None:
        self.proc.kill()
        self.proc.communicate()


@contextmanager
def board_process(*args: str, cwd: str | Path | None = None) -> Iterator[BoardProcess]:
    """`appmode board ARGS` while the block runs."""
    board = BoardProcess(*args, cwd=cwd)
    try:
        yield board
    finally:
        board.stop()
