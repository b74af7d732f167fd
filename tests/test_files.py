"""Files the user names are written (devices and FIFOs in place, links kept, the umask
honoured); files they did not name are neither replaced nor deleted."""

from __future__ import annotations

import errno
import os
import stat
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from appmode import files
from appmode.errors import AppmodeError


@contextmanager
def fifo_reader(path: Path) -> Iterator[list[bytes]]:
    """A FIFO at `path` with a reader collecting what is written into it."""
    os.mkfifo(path)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(path.read_bytes()), daemon=True)
    reader.start()
    try:
        yield got
    finally:
        reader.join(10)


def test_a_fifo_is_written_in_place(tmp_path: Path) -> None:
    path = tmp_path / "pipe"
    with fifo_reader(path) as got:
        files.write_whole(path, b"report\n", "report")
    assert got == [b"report\n"]
    assert stat.S_ISFIFO(path.lstat().st_mode), "the FIFO is still a FIFO"


def test_a_link_stays_a_link_and_its_target_is_written(tmp_path: Path) -> None:
    target = tmp_path / "real.xml"
    target.write_bytes(b"old")
    link = tmp_path / "link.xml"
    link.symlink_to(target.name)
    files.write_whole(link, b"new", "report")
    assert link.is_symlink() and target.read_bytes() == b"new"


def test_new_files_honour_the_umask_and_replaced_files_keep_their_mode(tmp_path: Path) -> None:
    old = os.umask(0o027)
    try:
        files.write_whole(tmp_path / "new", b"x", "report")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "new").stat().st_mode) == 0o640
    kept = tmp_path / "kept"
    kept.write_bytes(b"old")
    kept.chmod(0o604)
    files.write_whole(kept, b"new", "report")
    assert stat.S_IMODE(kept.stat().st_mode) == 0o604 and kept.read_bytes() == b"new"


def test_a_missing_folder_is_named(tmp_path: Path) -> None:
    for attempt in (files.check_writable, lambda p, w: files.write_whole(p, b"x", w)):
        with pytest.raises(AppmodeError, match=r"there is no folder .*nope; create it first"):
            attempt(tmp_path / "nope" / "x.png", "plot")
    with pytest.raises(AppmodeError, match="it is a folder"):
        files.check_writable(tmp_path, "plot")


def test_only_our_own_leftovers_are_removed(tmp_path: Path) -> None:
    names = [
        ".flash.json.swp",  # vim's
        ".flash.json.x",
        ".flash.json.0123abcd.appmode-tmp",  # ours
        ".other.json.0123abcd.appmode-tmp",  # ours, for another file
        ".flash.json.0123abcdz.appmode-tmp",
    ]
    for name in names:
        (tmp_path / name).write_bytes(b"")
    files.remove_leftovers(tmp_path / "flash.json")
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted(set(names) - {".flash.json.0123abcd.appmode-tmp"})


def test_a_failed_write_leaves_the_file_and_no_temporary_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "report.xml"
    target.write_bytes(b"precious")

    def full_disk(fd: int, data: object) -> int:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(files.os, "write", full_disk)
    with pytest.raises(AppmodeError, match=r"cannot write report .*report\.xml: No space left"):
        files.write_whole(target, b"new", "report")
    monkeypatch.undo()
    assert target.read_bytes() == b"precious"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.xml"]
