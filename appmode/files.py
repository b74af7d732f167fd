"""Writing the files a user names, without touching any they did not.

A regular file (or a new one) is replaced whole: a temporary file beside it, fsync, then
rename, so a reader never sees half of it. Anything else — a device such as /dev/null, a
FIFO, a terminal — is written in place, as a shell redirection would. A symbolic link
stays a link: its target is written. New files honour the umask; a replaced file keeps
its mode. Temporary files carry a name that only appmode uses (`LEFTOVER`).
"""

from __future__ import annotations

import errno
import os
import re
import stat
import sys
import time
from collections.abc import Iterable
from pathlib import Path

from appmode.errors import AppmodeError

_CLOEXEC = getattr(os, "O_CLOEXEC", 0)  # Windows has none (and no fork to leak into)
LEFTOVER = re.compile(r"\.(?P<name>.+)\.[0-9a-f]{8}\.appmode-tmp")
"""The name of a temporary file of ours: `.NAME.XXXXXXXX.appmode-tmp` beside NAME."""


def write_whole(path: str | os.PathLike[str], data: bytes, what: str) -> None:
    """Make `data` the content of `path`; AppmodeError naming `what` and the path if not."""
    write_streamed(path, [data], what)


def write_streamed(path: str | os.PathLike[str], chunks: Iterable[bytes], what: str) -> None:
    """Make the `chunks`, made as they are written, the content of `path` (a regular file
    only once all are written); AppmodeError naming `what` and the path if not. An
    AppmodeError from making them leaves the file as it was."""
    shown = os.fspath(path)
    target = Path(os.path.realpath(path))
    try:
        existing = os.stat(target)
    except FileNotFoundError:
        existing = None
    except OSError as exc:
        raise AppmodeError(f"cannot write {what} {shown}: {exc.strerror}") from None
    try:
        if existing is not None and not stat.S_ISREG(existing.st_mode):
            _write_in_place(target, chunks, what)
        else:
            _replace(target, chunks, existing)
    except OSError as exc:
        folder = target.parent
        if not folder.is_dir():
            raise AppmodeError(
                f"cannot write {what} {shown}: there is no folder {folder}; create it first"
            ) from None
        raise AppmodeError(f"cannot write {what} {shown}: {exc.strerror}") from None


def data_folder() -> Path:
    """appmode's folder in the user's data folder (not created here): XDG_DATA_HOME or
    ~/.local/share, ~/Library/Application Support on macOS, %LOCALAPPDATA% on Windows."""
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return base / "appmode"


def recordings_folder() -> Path:
    """Where recordings started from the web page go (`data_folder()`/recordings)."""
    return data_folder() / "recordings"


def new_recording(suffix: str) -> Path:
    """A new file in `recordings_folder()` (made if need be, for the user alone), named
    by the time, ending in `suffix` (its format's): the page asks for a recording,
    never names a file."""
    folder = recordings_folder()
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError as exc:
        raise AppmodeError(f"cannot make the folder {folder}: {exc.strerror}") from None
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for n in range(1000):
        path = folder / f"web-{stamp}{f'-{n}' if n else ''}{suffix}"
        try:
            os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _CLOEXEC, 0o600))
        except FileExistsError:
            continue
        except OSError as exc:
            raise AppmodeError(f"cannot write transcript {path}: {exc.strerror}") from None
        return path
    raise AppmodeError(f"cannot find a new name in {folder}: remove old recordings")


def check_writable(path: str | os.PathLike[str], what: str) -> None:
    """Before long work whose result goes to `path`: AppmodeError if it could not be
    written (no folder, no permission, a folder in its place, a FIFO nobody reads)."""
    shown = os.fspath(path)
    target = Path(os.path.realpath(path))
    if is_fifo(target):
        return  # opening it now would end its reader's input: it is checked as written
    if target.is_dir():
        raise AppmodeError(f"cannot write {what} {shown}: it is a folder; name a file")
    if not target.parent.is_dir():
        raise AppmodeError(
            f"cannot write {what} {shown}: there is no folder {target.parent}; create it first"
        )
    regular = not target.exists() or target.is_file()
    if not os.access(target.parent if regular else target, os.W_OK):
        raise AppmodeError(f"cannot write {what} {shown}: permission denied")


def remove_leftovers(path: str | os.PathLike[str]) -> None:
    """Delete the temporary files a killed write of `path` left beside it (ours only)."""
    target = Path(os.path.realpath(path))
    for entry in target.parent.glob(f".{target.name}.*.appmode-tmp"):
        match = LEFTOVER.fullmatch(entry.name)
        if match is not None and match["name"] == target.name and entry.is_file():
            entry.unlink(missing_ok=True)


def temporary_beside(target: Path) -> Path:
    """A new name for a temporary file beside `target`, of the LEFTOVER form."""
    return target.with_name(f".{target.name}.{os.urandom(4).hex()}.appmode-tmp")


def _write_in_place(target: Path, chunks: Iterable[bytes], what: str) -> None:
    fd = open_fifo(target, what) if is_fifo(target) else os.open(target, os.O_WRONLY | _CLOEXEC)
    try:
        for data in chunks:
            _write_all(fd, data)
    finally:
        os.close(fd)


def _replace(target: Path, chunks: Iterable[bytes], existing: os.stat_result | None) -> None:
    tmp = temporary_beside(target)
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
    try:
        try:
            if existing is not None:
                os.fchmod(fd, stat.S_IMODE(existing.st_mode))
            for data in chunks:
                _write_all(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_directory(target.parent)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


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


def open_fifo(path: str | os.PathLike[str], what: str, meanwhile: str = "Ctrl-C gives up") -> int:
    """The write end of the FIFO `path`. With no program reading it yet the open waits
    for one, as a FIFO does — saying so on stderr (with what happens `meanwhile`) rather
    than hanging in silence."""
    try:
        fd = os.open(path, os.O_WRONLY | getattr(os, "O_NONBLOCK", 0) | _CLOEXEC)
    except OSError as exc:
        if exc.errno != errno.ENXIO:
            raise
        sys.stderr.write(  # one write: a line of another thread's never cuts it
            f"appmode: waiting for a program to read the FIFO {os.fspath(path)} before "
            f"writing the {what} ({meanwhile})\n"
        )
        sys.stderr.flush()
        return os.open(path, os.O_WRONLY | _CLOEXEC)
    os.set_blocking(fd, True)
    return fd


def is_fifo(path: str | os.PathLike[str]) -> bool:
    try:
        return stat.S_ISFIFO(os.stat(path).st_mode)
    except OSError:
        return False


def say_if_fifo(path: str | os.PathLike[str]) -> None:
    """Reading a FIFO waits until a program writes it: say so, rather than hang in
    silence."""
    if is_fifo(path):
        print(
            f"appmode: waiting for a program to write to the FIFO {os.fspath(path)} "
            "(Ctrl-C gives up)",
            file=sys.stderr,
            flush=True,
        )


def read_limited(path: str, limit: int, hint: str) -> str:
    """A small text file a user names, read whole (UTF-8): OSError if it is not a regular
    file (a FIFO would wait for a writer, a device forever) or is over `limit` bytes
    (`hint` says why that is too much); UnicodeDecodeError if it is not text."""
    if not os.path.isfile(path):
        raise OSError(0, "not a regular file" if os.path.exists(path) else "no such file")
    if os.path.getsize(path) > limit:
        raise OSError(0, f"over {limit // 1000} kB: {hint}")
    with open(path, encoding="utf-8") as file:
        return file.read(limit + 1)
