"""Shared helpers live in tests/support/: decoders fed whole, split and byte by byte
(decoders.py), appmode run as a process and boards served by one (processes.py), and an
RFC 2217 server (rfc2217_server.py).

Every test runs with its own data folder: the console's history never touches the user's.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """`-n auto`: four workers for two cores. Most tests wait on boards, ptys and
    processes in real time, so more workers than cores keep the cores busy (4 min 50 s
    of CPU in a 4 min 6 s run; three workers took 5 min 10 s). Four once made real-time
    tests fail: each cause is gone (a test's symlink kept leading to a dead board's
    /dev/pts/N, which another worker's board then got; a send's earliness measured
    against a median that carries the load's latency; a sim:// recording out of time
    order)."""
    cores = os.cpu_count() or 1
    return 2 * cores


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Tests marked `alone` go last: pytest-xdist hands them out when the other workers
    are finishing, so a real-time run meets no load of this run's own (a starved board
    applies commands late, and the suite in real time holds it to ±0.3 s)."""
    items.sort(key=lambda item: item.get_closest_marker("alone") is not None)


@pytest.fixture(autouse=True)
def private_data_folder(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> Path:
    folder = tmp_path_factory.mktemp("data")
    monkeypatch.setenv("XDG_DATA_HOME", str(folder))
    return folder
