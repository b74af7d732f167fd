"""The board's non-volatile parameter store ("flash"), behind a small interface (§5).

`load()` gives the saved values, or None with a warning when there are none or they
cannot be read; it never raises. `save()` replaces them whole. The values are the nine
parameters, then gyro_calibration (the control port's tenth setting, §10) when it was
saved: a file written before it existed holds nine.
"""

from __future__ import annotations

import contextlib
import json
import os
import stat
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

from appmode.errors import AppmodeError
from appmode.files import remove_leftovers, write_whole
from appmode.protocol import params

FORMAT = "appmode-flash"
VERSION = 1
GYRO_CALIBRATION = "gyro_calibration"
"""The key of the tenth setting, beside `params`."""
MAX_SIZE = 64 * 1024
"""Bytes read at most: a flash file is a few hundred."""
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)  # Windows has none (and no fork to leak into)


def _try_lock(fd: int) -> bool:
    """Lock the open file `fd` for this process without waiting; False when another
    process holds it. The lock goes with the process: a killed board leaves none."""
    try:
        if sys.platform == "win32":
            import msvcrt

            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        else:
            import fcntl

            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


class Store(Protocol):
    def load(self) -> tuple[tuple[int, ...] | None, str | None]:
        """(saved values or None, warning or None)."""
        ...

    def save(self, values: Sequence[int]) -> None:
        """Keep `values`; AppmodeError (saying why) if they could not be kept."""
        ...

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
    """Flash in a JSON file, replaced whole on each save (`appmode.files.write_whole`).

    The file must be a regular file (or not exist yet): a device or a FIFO is refused.
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        real = Path(os.path.realpath(path))
        self._lock_path = real.with_name(f".{real.name}.appmode-lock")
        self._lock: int | None = None

    def lock(self) -> None:
        """Take the file for this board alone; AppmodeError if another board has it.

        The lock is an flock on `.NAME.appmode-lock` beside the file, removed on `close`.
        """
        try:
            kind = os.stat(self.path).st_mode
        except FileNotFoundError:
            kind = None
        except OSError as exc:
            raise AppmodeError(f"cannot use flash file {self.path}: {exc.strerror}") from None
        if kind is not None and not stat.S_ISREG(kind):
            raise AppmodeError(
                f"flash file {self.path} is not a regular file: name a file "
                f"(it is created on the first save)"
            )
        while True:
            try:
                fd = os.open(self._lock_path, os.O_RDWR | os.O_CREAT | _CLOEXEC, 0o666)
            except OSError as exc:
                raise AppmodeError(
                    f"cannot use flash file {self.path}: cannot create its lock "
                    f"{self._lock_path}: {exc.strerror}"
                ) from None
            if not _try_lock(fd):
                try:
                    holder = os.read(fd, 32).decode(errors="replace").strip()
                except OSError:  # Windows: the holder's lock keeps others from reading
                    holder = ""
                os.close(fd)
                holder = holder or "another process"
                raise AppmodeError(
                    f"flash file {self.path} is in use by another board (pid {holder}): give "
                    f"each board its own --flash file, or stop the other one"
                ) from None
            if _same_file(fd, self._lock_path):
                break
            os.close(fd)  # its holder removed it as we opened it: take the new one
        os.ftruncate(fd, 0)
        os.write(fd, str(os.getpid()).encode())
        self._lock = fd
        remove_leftovers(self.path)  # of a save that was killed

    def close(self) -> None:
        if self._lock is not None:
            with contextlib.suppress(OSError):  # Windows: not while open (removed below)
                self._lock_path.unlink(missing_ok=True)
            os.close(self._lock)
            self._lock = None
            if sys.platform == "win32":  # elsewhere a new holder's lock may be there now
                with contextlib.suppress(OSError):
                    self._lock_path.unlink(missing_ok=True)

    def load(self) -> tuple[tuple[int, ...] | None, str | None]:
        try:
            with open(self.path, "rb") as handle:
                data = handle.read(MAX_SIZE + 1)
        except FileNotFoundError:
            return None, f"{self.path}: no saved parameters yet, using factory defaults"
        except OSError as exc:
            return None, f"{self.path}: cannot read ({exc.strerror}), using factory defaults"
        try:
            values = _parse(data)
        except ValueError as exc:
            return None, f"{self.path}: {exc}; using factory defaults"
        return values, None

    def save(self, values: Sequence[int]) -> None:
        document: dict[str, object] = {
            "format": FORMAT,
            "version": VERSION,
            "params": {p.name: v for p, v in zip(params.PARAMS, values, strict=False)},
        }
        if len(values) > params.PARAM_COUNT:
            document[GYRO_CALIBRATION] = values[params.PARAM_COUNT]
        text = json.dumps(document, indent=2) + "\n"
        write_whole(self.path, text.encode(), "flash file")


def _same_file(fd: int, path: Path) -> bool:
    try:
        on_disk = os.stat(path)
    except FileNotFoundError:
        return False
    held = os.fstat(fd)
    return (held.st_dev, held.st_ino) == (on_disk.st_dev, on_disk.st_ino)


def _parse(data: bytes) -> tuple[int, ...]:
    if len(data) > MAX_SIZE:
        raise ValueError(f"over {MAX_SIZE:,} bytes, too large for a flash file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"not UTF-8 text (byte {exc.start + 1})") from None
    try:
        document = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"not valid JSON (line {exc.lineno}: {exc.msg})") from None
    except RecursionError:
        raise ValueError("not a flash file (nested too deeply)") from None
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
    if GYRO_CALIBRATION in document:
        value = document[GYRO_CALIBRATION]
        if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= params.U16:
            raise ValueError(f"{GYRO_CALIBRATION} must be an integer in 0–{params.U16}")
        values.append(value)
    return tuple(values)


def open_store(flash: str | None) -> Store:
    """The store for a running board: a locked JSON file when `flash` names one, else
    in memory. AppmodeError if another board holds the file."""
    if not flash:
        return MemoryStore()
    store = JsonFileStore(flash)
    store.lock()
    return store
