"""The board's non-volatile parameter store ("flash"), behind a small interface (§5).

`load()` gives the saved parameters, or None with a warning when there are none or they
cannot be read; it never raises. `save()` replaces them atomically.
"""

from __future__ import annotations

import fcntl
import json
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

from appmode.errors import AppmodeError
from appmode.protocol import params

FORMAT = "appmode-flash"
VERSION = 1


class Store(Protocol):
    def load(self) -> tuple[tuple[int, ...] | None, str | None]:
        """(saved values or None, warning or None)."""
        ...

    def save(self, values: Sequence[int]) -> None: ...

    def close(self) -> None:
        """Release the store (a file lock)."""
        ...


class MemoryStore:
    """Flash that lives as long as the object: the default for a simulated board."""

    def __init__(self, values: Sequence[int] | None = None) -> None:
        self.values = None if values is None else tuple(values)

    def load(self) -> tuple[tuple[int, ...] | None, str | None]:
        return self.values, None

    def save(self, values: Sequence[int]) -> None:
        self.values = tuple(values)

    def close(self) -> None:
        """Nothing to release."""


class JsonFileStore:
    """Flash in a JSON file, written atomically (temporary file, fsync, rename)."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self._lock: int | None = None

    def lock(self) -> None:
        """Take the file for this board alone; AppmodeError if another board has it.

        The lock is an flock on FILE.lock, held until `close` or the process ends.
        """
        lock_path = f"{self.path}.lock"
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise AppmodeError(f"cannot use flash file {self.path}: {exc.strerror}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.read(fd, 32).decode(errors="replace").strip() or "another process"
            os.close(fd)
            raise AppmodeError(
                f"flash file {self.path} is in use by another board (pid {holder}): give "
                f"each board its own --flash file, or stop the other one"
            ) from None
        os.ftruncate(fd, 0)
        os.write(fd, str(os.getpid()).encode())
        self._lock = fd
        for stale in self.path.parent.glob(f".{self.path.name}.*"):
            stale.unlink(missing_ok=True)  # temporary files of a save that was killed

    def close(self) -> None:
        if self._lock is not None:
            os.close(self._lock)
            self._lock = None

    def load(self) -> tuple[tuple[int, ...] | None, str | None]:
        try:
            text = self.path.read_text(encoding="utf-8")
        except FileNotFoundError:
            return None, f"{self.path}: no saved parameters yet, using factory defaults"
        except OSError as exc:
            return None, f"{self.path}: cannot read ({exc.strerror}), using factory defaults"
        try:
            values = _parse(text)
        except ValueError as exc:
            return None, f"{self.path}: {exc}; using factory defaults"
        return values, None

    def save(self, values: Sequence[int]) -> None:
        document = {
            "format": FORMAT,
            "version": VERSION,
            "params": {p.name: v for p, v in zip(params.PARAMS, values, strict=True)},
        }
        text = json.dumps(document, indent=2) + "\n"
        directory = self.path.parent
        fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", dir=directory)
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as handle:
                handle.write(text)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        _fsync_directory(directory)


def _fsync_directory(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _parse(text: str) -> tuple[int, ...]:
    try:
        document = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"not valid JSON (line {exc.lineno}: {exc.msg})") from None
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise ValueError(f"not an {FORMAT} file")
    if document.get("version") != VERSION:
        raise ValueError(f"unsupported version {document.get('version')!r}")
    saved = document.get("params")
    if not isinstance(saved, dict):
        raise ValueError("missing 'params' object")
    values = []
    for param in params.PARAMS:
        value = saved.get(param.name)
        if not isinstance(value, int) or isinstance(value, bool):
            raise ValueError(f"parameter {param.name} is missing or not an integer")
        values.append(value)
    error = params.values_error(values)
    if error is not None:
        raise ValueError(error)
    return tuple(values)


def open_store(flash: str | None) -> Store:
    """The store for a running board: a locked JSON file when `flash` names one, else
    in memory. AppmodeError if another board holds the file."""
    if not flash:
        return MemoryStore()
    store = JsonFileStore(flash)
    store.lock()
    return store
