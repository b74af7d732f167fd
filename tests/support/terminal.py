"""A command's stderr on a terminal (a pty), as a person running it sees it: what long
jobs show there (progress lines) and what they keep off a pipe."""

from __future__ import annotations

import os
import pty
import subprocess
import threading

from tests.support.processes import ROOT, appmode_cmd


def stderr_on_a_terminal(*args: str, timeout: float = 120) -> tuple[int, str]:
    """`appmode ARGS` with its stderr on a pty (stdout a pipe): its exit status and all
    the terminal was sent, read as it comes (a full pty would stall the command)."""
    master, slave = pty.openpty()
    chunks: list[bytes] = []

    def read() -> None:
        try:
            while chunk := os.read(master, 65536):
                chunks.append(chunk)
        except OSError:  # EIO: the terminal side is closed and all was read
            pass

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        done = subprocess.run(
            appmode_cmd(*args),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=slave,
            cwd=ROOT,
            timeout=timeout,
            check=False,
        )
    finally:
        os.close(slave)
        reader.join(10)
        os.close(master)
    return done.returncode, b"".join(chunks).decode(errors="replace")
