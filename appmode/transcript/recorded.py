"""A recorded session checked against a transcript's expectations, with no I/O.

`conform` plays a transcript's `>` lines itself; here a host under test has already
played them, and the board's recording says what happened. Each `>`/`2>` unit of the
expected transcript must appear among the recording's sent units, in order (other units
in between are allowed: a host may read its parameters too); each `<`/`2<` expectation
must be matched as `conform` matches it — in order, after the sends before it, within
its tolerance — with its time counted from when the last send before it in the file was
really made: an expectation 0.5 s after `> A` is due 0.5 s after the host sent `A`.
(So `@align` is not needed here, and has no effect.)
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

from appmode.line.wire import APP, UART2
from appmode.protocol.reader import RECEIVED, RECEIVED2, SENT, SENT2, PortsReader
from appmode.protocol.transcript import Transcript
from appmode.transcript.matcher import Check


@dataclass(frozen=True, slots=True)
class Verdict:
    failure: str | None = None
    """What failed (file:line, what was expected, what came instead), or None."""
    wait: float | None = None
    """When the recording ended before an expectation's deadline (the failure says so):
    that deadline, by which more recording may still meet it."""


@dataclass(frozen=True, slots=True)
class _Unit:
    index: int
    """The send (in `Check.sends`) this unit belongs to."""
    direction: str
    raw: bytes
    last: bool
    """The send's last unit: once matched, the whole line has been sent."""


class _Anchors:
    """Where each expectation's clock starts: the time the last send before it in the
    file was really made, less that send's time in the transcript."""

    def __init__(self, check: Check) -> None:
        self._check = check
        self._offsets: dict[int, float] = {}  # send index -> offset
        by_line = sorted(range(len(check.sends)), key=lambda i: check.sends[i].lineno)
        lines = [check.sends[i].lineno for i in by_line]
        self._before = []  # per expectation, the send last above it in the file (or -1)
        for exp in check.expectations:
            above = bisect.bisect_left(lines, exp.entry.lineno)
            self._before.append(by_line[above - 1] if above else -1)

    def sent(self, index: int, when: float) -> None:
        self._offsets[index] = when - self._check.sends[index].time

    def apply(self) -> None:
        """Set the check's clock for the expectation it waits for."""
        check = self._check
        if check.matched < len(check.expectations):
            check.offset = self._offsets.get(self._before[check.matched], 0.0)


def check_recorded(
    expected: Transcript, recording: Transcript, end: float | None = None
) -> Verdict:
    """Whether `recording` meets `expected`. `end` is the time up to which the recording
    is complete (a board's clock now); by default, its last line's time."""
    check = Check(expected)
    units = _send_units(check)
    anchors = _Anchors(check)
    reader = PortsReader(drive=check.needs.drive, layout=check.needs.profile.a_layout)
    k = 0
    for entry in recording.entries:
        anchors.apply()
        if check.active():
            check.on_time(entry.time)
        for shown, event in reader.feed(entry.direction, entry.data):
            if check.failure is not None:
                break
            anchors.apply()
            if shown in (RECEIVED, RECEIVED2):
                check.on_record(event, entry.time, UART2 if shown == RECEIVED2 else APP)
            elif k < len(units) and (shown, event.raw) == (units[k].direction, units[k].raw):
                unit = units[k]
                if k == 0 or units[k - 1].index != unit.index:
                    anchors.sent(unit.index, entry.time)
                if unit.last:
                    check.sent = unit.index + 1
                k += 1
        if check.failure is not None:
            return Verdict(check.failure)
    last = recording.entries[-1].time if recording.entries else 0.0
    return _unmet(check, anchors, units, k, last if end is None else max(end, last))


def _send_units(check: Check) -> list[_Unit]:
    """The expected sends, one decoded unit each, as a recorder writes them."""
    reader = PortsReader(drive=check.needs.drive)
    units: list[_Unit] = []
    for index, entry in enumerate(check.sends):
        found = [
            (shown, event.raw)
            for shown, event in reader.feed(entry.direction, entry.data)
            if shown in (SENT, SENT2)
        ]
        if not found:  # a unit left open (a frame cut short): its bytes as they are
            found = [(entry.direction, entry.data)]
        units += [
            _Unit(index, shown, raw, i == len(found) - 1) for i, (shown, raw) in enumerate(found)
        ]
    return units


def _unmet(check: Check, anchors: _Anchors, units: list[_Unit], k: int, end: float) -> Verdict:
    """What the recording, complete to `end`, never showed: the first in the file of the
    sends not made and the expectations not met."""
    path = check.transcript.path
    send = check.sends[units[k].index] if k < len(units) else None
    exp = None if check.done else check.expectations[check.matched]
    if send is not None and (exp is None or send.lineno < exp.entry.lineno):
        return Verdict(
            f"{path}:{send.lineno}: expected the host to send {send.text}; the recording "
            f"(to {end:.3f} s) has no such unit after the sends before it"
        )
    if exp is None:
        return Verdict()
    anchors.apply()
    due = exp.entry.time + check.offset
    if end < due + exp.tolerance:
        seen = next(iter(check.closest.values()), None)
        failure = (
            f"{path}:{exp.entry.lineno}: expected {exp.pattern.text} at {due:.3f} s "
            f"(±{exp.tolerance:g} s); the recording ends at {end:.3f} s"
            + (f" (it got {seen[1]})" if seen else "")
            + ": wait until the board has sent it before checking"
        )
        return Verdict(failure, due + exp.tolerance)
    check.on_time(end)
    return Verdict(check.failure)
