"""`appmode web` as a process, beside a board process whose host bytes are recorded."""

from __future__ import annotations

import re
import signal
import subprocess
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from tests.support.processes import (
    BoardProcess,
    board_process,
    sent_lines,
    serving,
    stop_process,
)


@dataclass
class WebProcess:
    proc: subprocess.Popen[str]
    address: str
    """The page's address, with its token."""
    board: BoardProcess
    record: Path

    @property
    def origin(self) -> str:
        return self.address.split("/?", 1)[0]

    @property
    def token(self) -> str:
        return self.address.rsplit("=", 1)[1]

    def sent(self) -> list[str]:
        """What the board received on its APP port, one unit a line."""
        return sent_lines(self.record) if self.record.exists() else []

    def frames(self) -> list[str]:
        """What the board received on its control port, a frame a line (hex)."""
        return [frame for _, frame in self.timed_frames()]

    def timed_frames(self) -> list[tuple[float, str]]:
        """The frames with the board's times of them (seconds)."""
        if not self.record.exists():
            return []
        lines = self.record.read_text().splitlines()
        split = [line.split(" ", 2) for line in lines if " 2> " in line]
        return [(float(when), frame) for when, _, frame in split]

    def stop(self, sig: int = signal.SIGTERM) -> tuple[int, str]:
        """Stop it (SIGTERM by default): its exit status and stderr."""
        err = stop_process(self.proc, sig)
        return self.proc.returncode, err


@contextmanager
def web_process(
    tmp_path: Path,
    *args: str,
    uart2: bool = False,
    bluetooth: str = "",
    profile: str = "sheet",
    chassis: bool = False,
) -> Iterator[WebProcess]:
    """A board on a pty recording what it receives, and `appmode web` driving it (its
    data folder, where a certificate is kept, in `tmp_path`); with `uart2`, over the
    board's control port; with `bluetooth` "ble" or "spp", over that module of the board
    behind the BlueZ stand-in; with `chassis`, a WHEELTEC profile's chassis port; the
    board and the page of `profile`."""
    record = tmp_path / "board.transcript"
    where = "--bluetooth" if bluetooth else "--pty"
    if profile != "sheet":
        args = (*args, "--profile", profile)
    with board_process(where, "--record", str(record), "--quiet", "--profile", profile) as board:
        bus = {"DBUS_SYSTEM_BUS_ADDRESS": board.details["bus"]} if bluetooth else {}
        if bluetooth:
            address = board.details[bluetooth].split()[0]
            board.url = f"{'ble' if bluetooth == 'ble' else 'bt'}://{address}"
        port = (board.uart2, "--uart2") if uart2 else (str(board.chassis), "--chassis")
        proc, line = serving(
            "web",
            *(port if uart2 or chassis else (board.url,)),
            "--listen",
            "127.0.0.1:0",
            *args,
            data=tmp_path / "data",
            env=bus,
        )
        found = re.match(r"web: (https?://\S+)", line)
        web = WebProcess(proc, found.group(1) if found else "", board, record)
        try:
            assert found, f"appmode web printed {line!r}: {web.stop()[1]}"
            yield web
        finally:
            web.stop()


def wait_sent(web: WebProcess, wanted: str, timeout: float = 5.0) -> list[str]:
    """Wait until the board has received `wanted` last; what it received."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        sent = web.sent()
        if sent and sent[-1] == wanted:
            return sent
        time.sleep(0.02)
    raise AssertionError(f"the board's last unit is not {wanted!r}: {web.sent()[-8:]}")


def wait_frame(web: WebProcess, wanted: str, timeout: float = 5.0) -> list[str]:
    """Wait until the control port's last frame starts with `wanted`; the frames."""
    return wait_frames(
        web, lambda frames: bool(frames) and frames[-1].startswith(wanted), f"{wanted}…", timeout
    )


def wait_frames(
    web: WebProcess, found: Callable[[list[str]], bool], what: str, timeout: float = 5.0
) -> list[str]:
    """Wait until `found(frames)` holds of the control port's frames; the frames."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        frames = web.frames()
        if found(frames):
            return frames
        time.sleep(0.02)
    raise AssertionError(f"the control port sent no {what}: {web.frames()[-5:]}")
