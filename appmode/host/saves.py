"""What appmode asked each board to save (`params --save`), kept in the user's data folder
so that the save can be checked after the board restarts (`params --verify-saved`): the
protocol has no acknowledgement, so a save cannot be confirmed any other way."""

from __future__ import annotations

import json
import time
from pathlib import Path

from appmode.errors import AppmodeError
from appmode.files import data_folder, write_whole
from appmode.protocol import params


def path() -> Path:
    return data_folder() / "saved.json"


def _load() -> dict[str, dict[str, object]]:
    try:
        document = json.loads(path().read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return {}
    return document if isinstance(document, dict) else {}


def remember(url: str, values: tuple[int, ...]) -> None:
    """Note that `values` were saved on the board at `url`, now; AppmodeError naming the
    file if it cannot be written."""
    document = _load()
    document[url] = {"values": list(values), "at": time.strftime("%Y-%m-%d %H:%M:%S")}
    try:
        path().parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise AppmodeError(f"cannot write saved parameters {path()}: {exc.strerror}") from None
    write_whole(path(), (json.dumps(document, indent=2) + "\n").encode(), "saved parameters")


def recall(url: str) -> tuple[tuple[int, ...], str] | None:
    """The values last saved on `url` and when, or None if none were (or the file is
    unreadable)."""
    entry = _load().get(url)
    if not isinstance(entry, dict):
        return None
    values, at = entry.get("values"), entry.get("at")
    if (
        not isinstance(values, list)
        or len(values) != params.PARAM_COUNT
        or not all(isinstance(v, int) and not isinstance(v, bool) for v in values)
        or not isinstance(at, str)
    ):
        return None
    return tuple(values), at
