"""Which processes hold a device open, where the OS tells (Linux's /proc); elsewhere
nobody is named."""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass

PROC = "/proc"


@dataclass(frozen=True, slots=True)
class Holder:
    pid: int
    name: str
    locks: bool
    """It holds the device's lock (pyserial's `exclusive`, flock): the one that makes
    others' opens fail."""

    def __str__(self) -> str:
        return f"{self.name} (pid {self.pid}{', holding its lock' if self.locks else ''})"


def holders(device: str, proc: str = PROC) -> list[Holder]:
    """The processes other than this one with `device` open, lockers first; [] where the
    OS does not tell."""
    try:
        stat = os.stat(device)
        target = os.path.realpath(device)
    except OSError:
        return []
    lockers = _lockers(stat.st_ino, stat.st_dev, proc)
    found: dict[int, Holder] = {}
    with contextlib.suppress(OSError):
        for entry in os.scandir(proc):
            if not entry.name.isdigit() or int(entry.name) == os.getpid():
                continue
            pid = int(entry.name)
            if _has_open(f"{entry.path}/fd", target):
                found[pid] = Holder(pid, _name(entry.path), pid in lockers)
    for pid in lockers - found.keys():
        if pid != os.getpid():
            found[pid] = Holder(pid, _name(f"{proc}/{pid}"), True)
    return sorted(found.values(), key=lambda h: (not h.locks, h.pid))


def terminal_of(device: str, proc: str = PROC) -> list[Holder]:
    """The processes whose controlling terminal is `device`: a shell's pseudo-terminal,
    say, never a board's (appmode board's pty is no program's terminal). [] where the OS
    does not tell."""
    try:
        number = os.stat(device).st_rdev
    except OSError:
        return []
    if not hasattr(os, "major") or not number:
        return []
    major, minor = os.major(number), os.minor(number)
    tty_nr = (minor & 0xFF) | (major << 8) | ((minor & ~0xFF) << 12)  # /proc/PID/stat's
    found = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(proc):
            if not entry.name.isdigit():
                continue
            try:
                with open(f"{entry.path}/stat", "rb") as file:
                    fields = file.read(4096).rsplit(b")", 1)[1].split()
            except (OSError, IndexError):
                continue
            if len(fields) > 4 and fields[4] == b"%d" % tty_nr:
                found.append(Holder(int(entry.name), _name(entry.path), False))
    return sorted(found, key=lambda h: h.pid)


def _has_open(fds: str, target: str) -> bool:
    with contextlib.suppress(OSError):
        for fd in os.scandir(fds):
            with contextlib.suppress(OSError):
                if os.readlink(fd.path) == target:
                    return True
    return False


def _name(process: str) -> str:
    """The process's command line (its program's name, then up to three words),
    shortened; else its name."""
    try:
        with open(f"{process}/cmdline", "rb") as file:
            words = [w.decode(errors="replace") for w in file.read(4096).split(b"\0") if w]
    except OSError:
        words = []
    if words:
        words[0] = os.path.basename(words[0])
    text = " ".join(" ".join(words[:4]).split())
    if not text:
        with contextlib.suppress(OSError), open(f"{process}/comm") as file:
            text = file.read().strip()
    return text[:60] or "?"


def _lockers(inode: int, device: int, proc: str) -> set[int]:
    """Processes with a flock on the file (`/proc/locks`: `N: FLOCK ADVISORY WRITE PID
    MAJ:MIN:INODE …`)."""
    if not hasattr(os, "major"):  # Windows: no /proc either
        return set()
    wanted = f"{os.major(device):02x}:{os.minor(device):02x}:{inode}"
    pids: set[int] = set()
    with contextlib.suppress(OSError), open(f"{proc}/locks") as file:
        for line in file:
            fields = line.split()
            if len(fields) > 5 and fields[1] == "FLOCK" and fields[5] == wanted:
                with contextlib.suppress(ValueError):
                    pids.add(int(fields[4]))
    return pids
