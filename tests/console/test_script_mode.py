"""Issue 69.10: script mode's `status` printed the console's key grid and its keys
("Ctrl-Q quit"), which a script cannot press."""

from __future__ import annotations

import pytest

from tests.support.processes import run


@pytest.mark.parametrize("uart2", [False, True], ids=["app", "uart2"])
def test_a_script_s_status_is_the_rows_without_keys(uart2: bool) -> None:
    done = run("drive", "sim://", *(["--uart2"] if uart2 else []), stdin=b"status\n")
    assert done.returncode == 0, done.stderr
    assert " appmode drive" in done.stdout and " link up" in done.stdout
    assert "params" in done.stdout or "settings" in done.stdout
    for keys in ("Ctrl-Q quit", "space stop", "? help", "↖"):
        assert keys not in done.stdout, done.stdout
