"""Cars shared with `appmode share` on this machine's loopback (no namespaces needed):
a board on a pty recording what it receives, and its share, always stopped after."""

from __future__ import annotations

import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from appmode.testing.process import BoardProcess
from tests.support.processes import (
    ROOT,
    appmode_cmd,
    board_process,
    sent_lines,
    serving,
    stop_process,
)

KEY = "fleet key"
HOST_KEY = "room host key"
"""The hosts' key of every share and router here (a test's own: none is kept in the
user's data folder)."""


@dataclass
class SharedBoard:
    board: BoardProcess
    share: subprocess.Popen[str]
    url: str
    """The zenoh:// URL the share printed."""
    record: Path

    @property
    def endpoint(self) -> str:
        """Where the share listens: tcp/127.0.0.1:PORT."""
        return self.url.split("connect=", 1)[1].split("&", 1)[0]

    def stop(self) -> str:
        """SIGTERM the share: its stderr."""
        return stop_process(self.share)

    def sent(self) -> list[str]:
        """What the board received on its APP port, a unit a line."""
        return sent_lines(self.record) if self.record.exists() else []


@contextmanager
def shared_board(folder: Path, name: str, *args: str, uart2: bool = False) -> Iterator[SharedBoard]:
    """The board `name` (recording into `folder`, its data folder there too) shared on
    loopback with KEY, with `uart2` its control port too; `args` go to share
    (`--connect` another, `--tls`)."""
    record = folder / f"{name}.transcript"
    with board_process("--pty", "--quiet", "--record", str(record)) as board:
        share, line = serving(
            "share",
            board.url,
            *((board.uart2,) if uart2 else ()),
            "--name",
            name,
            "--listen",
            "tcp/127.0.0.1:0",
            "--key",
            KEY,
            "--host-key",
            HOST_KEY,
            *args,
            data=folder / "data",
        )
        line = line.strip()
        try:
            assert line.startswith("zenoh://"), f"share printed {line!r}: {stop_process(share)}"
            yield SharedBoard(board, share, line, record)
        finally:
            stop_process(share)


@contextmanager
def routed(folder: Path) -> Iterator[tuple[str, SharedBoard]]:
    """An `appmode router` on loopback (with KEY and HOST_KEY) and the car `car` shared
    through it: the router's endpoint, where clients connect, and the car. The router
    ends cleanly after (SIGTERM: exit 0, no traceback)."""
    router = subprocess.Popen(
        appmode_cmd("router", "--listen", "tcp/127.0.0.1:0", "--key", KEY, "--host-key", HOST_KEY),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        assert router.stdout is not None
        endpoint = router.stdout.readline().split()[-1]
        assert endpoint.startswith("tcp/127.0.0.1:") and not endpoint.endswith(":0"), endpoint
        with shared_board(folder, "car", "--connect", endpoint) as car:
            yield endpoint, car
    finally:
        err = stop_process(router)
    assert router.returncode == 0 and "Traceback" not in err, err
