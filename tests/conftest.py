"""Shared helpers live in tests/support/: decoders fed whole, split and byte by byte
(decoders.py), appmode run as a process and boards served by one (processes.py), and an
RFC 2217 server (rfc2217_server.py).

Every test runs with its own data folder: the console's history never touches the user's.
"""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(autouse=True)
def private_data_folder(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> Path:
    folder = tmp_path_factory.mktemp("data")
    monkeypatch.setenv("XDG_DATA_HOME", str(folder))
    return folder
