"""Shared helpers live in tests/support/: decoders fed whole, split and byte by byte
(decoders.py), appmode run as a process and boards served by one (processes.py), and an
RFC 2217 server (rfc2217_server.py).

Every test runs with its own data folder: the console's history never touches the user's.
"""

from __future__ import annotations

import compileall
import os
from pathlib import Path

import pytest


def pytest_configure(config: pytest.Config) -> None:
    """The package's bytecode, brought up to date once before the run (by the controller,
    not each worker): the suite starts appmode some 800 times, and where
    PYTHONDONTWRITEBYTECODE is set (as on this machine's image) each start compiled every
    module again, 0.12 s of its 0.4 s."""
    if not hasattr(config, "workerinput"):
        compileall.compile_dir(Path(__file__).parents[1] / "appmode", quiet=2)


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """`-n auto`: two workers a core. Most tests wait on boards, ptys and processes in
    real time, so more workers than cores keep the cores busy: with the package's
    bytecode cached (pytest_configure) three ran the suite in 4 min 56 s idle here, four
    in 3 min 54 s. Four had starved a script's session past the stop guard's 0.25 s;
    the guard now counts only time the process ran (session/authority.py)."""
    return 2 * (os.cpu_count() or 1)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The page's tests in Chromium go first and tests marked `alone` last: pytest-xdist
    hands the last out while the other workers are finishing, so a real-time run meets
    no load of this run's own (a starved board applies commands late, and the suite in
    real time holds it to ±0.3 s), and the browsers, whose heartbeats a burst of boards
    starves past the page's 0.25-s lease (a held direction then stops, as it must), are
    done before it (they came last by name, beside it). Within each, the long ones
    (`slow`) first: a long test handed out last keeps the run going after the rest."""
    items.sort(
        key=lambda item: (
            item.get_closest_marker("alone") is not None,
            not item.nodeid.startswith("tests/web/"),
            item.get_closest_marker("slow") is None,
        )
    )


@pytest.fixture(autouse=True)
def private_data_folder(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> Path:
    folder = tmp_path_factory.mktemp("data")
    monkeypatch.setenv("XDG_DATA_HOME", str(folder))
    return folder
