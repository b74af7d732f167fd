"""Exact wake-ups, on Linux; elsewhere nothing changes.

- Timer slack: Linux wakes a sleeping thread up to 50 µs after its timeout, so that
  wake-ups can be batched; a thread that keeps deadlines asks for 1 µs.
- Timeouts to the microsecond: epoll counts its timeout in whole milliseconds, rounded
  up, so a wait of 3.2 ms lasts 4; `select_exactly` waits on the epoll descriptor itself
  with select(2), whose timeout is in microseconds.
- A short slice: on a busy machine a woken thread waits until the scheduler lets it run.
  Since Linux 6.12 a thread may ask for a shorter slice (`sched_setattr`'s
  `sched_runtime`, no privilege needed); its deadlines come sooner, so it runs at once
  on waking, in shorter turns, with the same share of the processor. Older kernels
  ignore the request.
"""

from __future__ import annotations

import ctypes
import platform
import select
import selectors
import sys
from collections.abc import Iterator
from contextlib import contextmanager

PR_SET_TIMERSLACK, PR_GET_TIMERSLACK = 29, 30
SLACK_NS = 1000
SLICE_NS = 100_000
"""The slice asked for: the kernel's shortest (0.1 ms)."""
SCHED_OTHER = 0
SCHED_FLAG_RESET_ON_FORK = 0x01
SCHED_ATTR = {  # (sched_setattr, sched_getattr) by machine
    "x86_64": (314, 315),
    "aarch64": (274, 275),
    "arm64": (274, 275),
    "riscv64": (274, 275),
    "loongarch64": (274, 275),
    "armv8l": (380, 381),
    "armv7l": (380, 381),
    "armv6l": (380, 381),
    "i686": (351, 352),
    "i386": (351, 352),
    "ppc64le": (355, 356),
    "ppc64": (355, 356),
    "s390x": (345, 346),
}
IN_32_BITS = {"x86_64": "i686", "aarch64": "armv7l", "arm64": "armv7l"}
"""The machine whose numbers a 32-bit program uses on these 64-bit kernels (a Raspberry
Pi's 32-bit system on its 64-bit kernel, say): `platform.machine` names the kernel's."""


def syscall_numbers(machine: str, pointer_bytes: int) -> tuple[int, int] | None:
    """(sched_setattr, sched_getattr) for a program of `pointer_bytes` pointers on a
    kernel of `machine`, or None for a machine not in SCHED_ATTR."""
    if pointer_bytes == 4:
        machine = IN_32_BITS.get(machine, machine)
    return SCHED_ATTR.get(machine)


class SchedAttr(ctypes.Structure):
    """The kernel's `struct sched_attr`, first version (48 bytes)."""

    _fields_ = [
        ("size", ctypes.c_uint32),
        ("policy", ctypes.c_uint32),
        ("flags", ctypes.c_uint64),
        ("nice", ctypes.c_int32),
        ("priority", ctypes.c_uint32),
        ("runtime", ctypes.c_uint64),
        ("deadline", ctypes.c_uint64),
        ("period", ctypes.c_uint64),
    ]


@contextmanager
def exact_wakeups() -> Iterator[None]:
    """This thread's sleeps and select timeouts end within ~1 µs of their time, and it
    runs at once when woken, while the block runs; the thread's settings are restored
    after."""
    if sys.platform != "linux":
        yield
        return
    try:
        libc = ctypes.CDLL(None, use_errno=True)
    except OSError:
        yield
        return
    with _slack(libc), _short_slice(libc):
        yield


def select_exactly(
    sel: selectors.BaseSelector, timeout: float
) -> list[tuple[selectors.SelectorKey, int]]:
    """`sel.select(timeout)`, ending within a microsecond of `timeout`, not at the next
    whole millisecond as an epoll selector's wait does: the wait is on the epoll
    descriptor, readable once an event is pending, with select(2)."""
    if timeout <= 0 or sys.platform != "linux" or not isinstance(sel, selectors.EpollSelector):
        return sel.select(timeout)
    try:
        ready, _, _ = select.select([sel.fileno()], [], [], timeout)
    except (ValueError, OverflowError):  # beyond what select(2) takes: FD_SETSIZE, time_t
        return sel.select(timeout)
    return sel.select(0) if ready else []


@contextmanager
def _slack(libc: ctypes.CDLL) -> Iterator[None]:
    """A timer slack of SLACK_NS."""
    old = libc.prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0)
    changed = old > 0 and libc.prctl(PR_SET_TIMERSLACK, SLACK_NS, 0, 0, 0) == 0
    try:
        yield
    finally:
        if changed:
            libc.prctl(PR_SET_TIMERSLACK, old, 0, 0, 0)


def _numbers() -> tuple[int, int] | None:
    return syscall_numbers(platform.machine(), ctypes.sizeof(ctypes.c_void_p))


def sched_attr(libc: ctypes.CDLL) -> SchedAttr | None:
    """This thread's scheduling attributes, or None where they cannot be read."""
    numbers = _numbers()
    attr = SchedAttr()
    if numbers is None or libc.syscall(numbers[1], 0, ctypes.byref(attr), 48, 0) != 0:
        return None
    return attr


def _set(libc: ctypes.CDLL, attr: SchedAttr, runtime: int) -> bool:
    """`attr`'s policy, nice value and reset-on-fork flag, with a slice of `runtime`."""
    numbers = _numbers()
    flags = attr.flags & SCHED_FLAG_RESET_ON_FORK
    new = SchedAttr(48, attr.policy, flags, attr.nice, 0, runtime)
    return numbers is not None and libc.syscall(numbers[0], 0, ctypes.byref(new), 0) == 0


@contextmanager
def _short_slice(libc: ctypes.CDLL) -> Iterator[None]:
    """A slice of SLICE_NS for a thread of the normal policy (its nice value kept)."""
    old = sched_attr(libc)
    changed = old is not None and old.policy == SCHED_OTHER and _set(libc, old, SLICE_NS)
    try:
        yield
    finally:
        if changed and old is not None:
            _set(libc, old, old.runtime)
