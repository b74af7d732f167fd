"""Each test of the console in tmux has a tmux server of its own (test_console_tmux.TMUX)."""

from __future__ import annotations

import itertools
import shutil
import subprocess
from collections.abc import Iterator

import pytest

from tests.console.test_console_tmux import PREFIX, TMUX

_servers = itertools.count(1)


@pytest.fixture(autouse=True)
def own_tmux_server() -> Iterator[None]:
    """A new server name per test; the server, and any console left in it, ended after."""
    TMUX[2] = f"{PREFIX}-{next(_servers)}"
    yield
    if shutil.which("tmux"):
        subprocess.run([*TMUX, "kill-server"], capture_output=True, check=False)
