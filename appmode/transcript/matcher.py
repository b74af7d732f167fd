"""Transcripts as conformance tests (docs/design.md, "Contracts"): the matcher, with no I/O.

`>` lines are sent at their times (`2>` lines on UART2, `c>` on a chassis port). Each
`<` line that is a record is an expectation, to be matched in file order by a record the
board sends (each `2<` line of hex pairs by a reply, report or undecodable run on UART2
with those bytes, each `c<` line by a chassis port's frame, `??` matching any byte); `*`
in place of a field matches
any integer, `LO..HI` any integer from LO to HI (`{A0:4..16:*:0}$`). A record matches an
expectation only once every `>` line before it in the file has been sent, and within
`tolerance` seconds of its time (default TOLERANCE). Other records are ignored — unless
`@strict on`, when each record must match the next expectation. `<` lines that are not
records (bytes that decoded to nothing) expect nothing. `@board profile=… drive=…
start=power-up` names the board the transcript needs: its profile (default sheet), drive
type, and whether time 0 is the board's power-up. `@align` makes the next expectation
match whenever it comes (after its sends, by its time + tolerance), and shifts the times
of the expectations after it by how early or late it came: timing is then checked
against the board's own rhythm. A `>` line sent late (a runner held up by a loaded
machine) shifts the expectations that follow it by as much: the board is judged on when
it got each command, not on when it was due.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field

from appmode.board.profiles import SHEET, Profile, recorded_profile
from appmode.errors import AppmodeError, InvalidValue
from appmode.line.wire import APP as APP_PORT
from appmode.line.wire import CHASSIS as CHASSIS_PORT
from appmode.line.wire import UART2 as UART2_PORT
from appmode.protocol import app
from appmode.protocol.escaping import escape
from appmode.protocol.params import DriveType
from appmode.protocol.reader import (
    RECEIVED,
    RECEIVED2,
    RECEIVED_CHASSIS,
    SENT,
    SENT2,
    SENT_CHASSIS,
)
from appmode.protocol.reader import Event as Unit
from appmode.protocol.transcript import MAX_TIME, Directive, Entry, Transcript, uart2_bytes

TOLERANCE = 0.5
PORT_OF = {
    SENT: APP_PORT,
    RECEIVED: APP_PORT,
    SENT2: UART2_PORT,
    RECEIVED2: UART2_PORT,
    SENT_CHASSIS: CHASSIS_PORT,
    RECEIVED_CHASSIS: CHASSIS_PORT,
}
"""The port of each direction."""
BYTES_PORTS = (UART2_PORT, CHASSIS_PORT)
"""The ports whose lines are hex pairs: their expectations are bytes."""
_FIELD = r"(?:-?\d+(?:\.\.-?\d+)?|\*)"
_PATTERN = re.compile(rf"\{{([A-Za-z])({_FIELD}(?::{_FIELD})*)?\}}\$?")
Span = tuple[int, int] | None
"""A field of a pattern: the integers it matches, from–to, or None for any."""


@dataclass(frozen=True, slots=True)
class Pattern:
    """A record with `*` wildcards: `{A*:500:*:0}$`."""

    letter: str
    fields: tuple[Span, ...]
    text: str

    @property
    def what(self) -> str:
        return f"{self.letter} record"

    def matches(self, record: Unit) -> bool:
        if not isinstance(record, app.RECORDS):
            return False
        letter, values = record.letter, record.values
        return (
            letter == self.letter
            and len(values) == len(self.fields)
            and all(
                f is None or f[0] <= v <= f[1] for f, v in zip(self.fields, values, strict=True)
            )
        )


@dataclass(frozen=True, slots=True)
class BytesPattern:
    """A unit of UART2 or a chassis port as hex pairs, `??` for any byte: `23 01 ?? ??`."""

    data: bytes
    mask: bytes
    text: str

    @property
    def what(self) -> str:
        return f"unit {self.data[:1].hex().upper()}"

    def matches(self, unit: Unit) -> bool:
        raw = unit.raw
        return len(raw) == len(self.data) and all(
            (a ^ b) & m == 0 for a, b, m in zip(raw, self.data, self.mask, strict=True)
        )


def parse_pattern(text: str) -> Pattern | None:
    """The pattern of a `<` payload, or None when it is not a record."""
    match = _PATTERN.fullmatch(text)
    if match is None:
        return None
    body = match.group(2) or ""
    fields = tuple(_span(f) for f in body.split(":")) if body else ()
    return Pattern(match.group(1), fields, text)


MAX_DIGITS = 20
"""Digits a field of an expectation may have: a record's fields are 32-bit numbers."""


def _span(text: str) -> Span:
    if text == "*":
        return None
    low, _, high = text.partition("..")
    if max(len(low), len(high)) > MAX_DIGITS:
        raise InvalidValue(
            f"a field of {max(len(low), len(high)):,} digits: a record's fields are whole "
            f"numbers of at most {MAX_DIGITS} digits"
        )
    span = (int(low), int(high or low))
    if span[0] > span[1]:
        raise InvalidValue(f"{text}: a field LO..HI needs LO <= HI")
    return span


@dataclass(frozen=True, slots=True)
class Expectation:
    entry: Entry
    pattern: Pattern | BytesPattern
    tolerance: float
    strict: bool
    after: float
    """Time of the last `>` line before it in the file: it cannot be matched earlier."""
    align: bool = False
    """`@align` before it: its match time becomes the time base of the lines after it."""


@dataclass(frozen=True, slots=True)
class BoardNeeds:
    profile: Profile = SHEET
    drive: DriveType | None = None
    power_up: bool = False
    """Time 0 is the board's power-up: only a board started for the run can pass it."""


@dataclass
class Check:
    """One transcript being run against a board."""

    transcript: Transcript
    sends: list[Entry] = field(default_factory=list)
    expectations: list[Expectation] = field(default_factory=list)
    needs: BoardNeeds = field(default_factory=BoardNeeds)
    failure: str | None = None
    offset: float = 0.0
    """Shift of expectation times, set by an `@align` match."""
    sent: int = 0
    late: list[float] = field(default_factory=list)
    """How late each `>` line sent so far went out (seconds, never negative)."""
    matched: int = 0
    closest: dict[str, tuple[float, str]] = field(default_factory=dict)
    """Per letter, the unmatched record nearest the expectation's time: what came instead."""
    _end: float | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        tolerance, strict, last_send, align = TOLERANCE, False, 0.0, False
        for item in self.transcript.items:
            if isinstance(item, Directive) and item.name == "align":
                align = True
            elif isinstance(item, Directive):
                tolerance, strict = self._directive(item, tolerance, strict)
            elif item.direction in (SENT, SENT2, SENT_CHASSIS):
                self.sends.append(item)
                last_send = max(last_send, item.time)
            elif (pattern := _expected(item, self.transcript.path)) is not None:
                self.expectations.append(
                    Expectation(item, pattern, tolerance, strict, last_send, align)
                )
                align = False
        self.sends.sort(key=lambda e: e.time)

    def _directive(self, item: Directive, tolerance: float, strict: bool) -> tuple[float, bool]:
        where = f"{self.transcript.path}:{item.lineno}"
        if item.name == "tolerance":
            try:
                ok = len(item.args) == 1 and item.args[0].isascii()
                tolerance = float(item.args[0]) if ok else -1.0
            except ValueError:
                tolerance = -1.0
            if not 0 <= tolerance <= MAX_TIME:
                raise AppmodeError(
                    f"{where}: @tolerance takes seconds in 0–{MAX_TIME:g}, e.g. @tolerance 0.3"
                )
        elif item.name == "strict":
            if item.args not in (("on",), ("off",)):
                raise AppmodeError(f"{where}: @strict takes on or off")
            strict = item.args[0] == "on"
        else:
            self.needs = board_needs(item.args, where)
        return tolerance, strict

    # ------------------------------------------------------------ driving it

    @property
    def done(self) -> bool:
        return self.failure is not None or (
            self.matched == len(self.expectations) and self.sent == len(self.sends)
        )

    @property
    def end(self) -> float:
        """When the run is over at the latest (worked out once: runners ask each step)."""
        if self._end is None:
            last = max((e.entry.time + e.tolerance for e in self.expectations), default=0.0)
            self._end = max(last, self.transcript.duration)
        return self._end

    def due(self, now: float) -> list[tuple[str, bytes]]:
        """The `>`, `2>` and `c>` payloads to send by `now`, each with its port."""
        out = []
        while self.sent < len(self.sends) and self.sends[self.sent].time <= now:
            entry = self.sends[self.sent]
            out.append((PORT_OF[entry.direction], entry.data))
            self.late.append(max(0.0, now - entry.time))
            self.sent += 1
        return out

    @property
    def uses_uart2(self) -> bool:
        return self.uses(UART2_PORT)

    def uses(self, port: str) -> bool:
        """Some line sends or expects on `port`."""
        return any(PORT_OF[e.direction] == port for e in self.sends) or any(
            PORT_OF[e.entry.direction] == port for e in self.expectations
        )

    def next_time(self) -> float | None:
        """The next time something is due: a send, or an expectation's deadline."""
        if self.done:
            return None
        times = []
        if self.sent < len(self.sends):
            times.append(self.sends[self.sent].time)
        if self.matched < len(self.expectations):
            exp = self.expectations[self.matched]
            times.append(self._deadline(exp))
        return min(times) if times else None

    def on_record(self, record: Unit, now: float, port: str = APP_PORT) -> None:
        """A unit the board sent on `port`, decoded, at `now`."""
        if self.done or self.matched >= len(self.expectations):
            return
        exp = self.expectations[self.matched]
        if PORT_OF[exp.entry.direction] != port:
            return  # another port's: ignored like unmentioned telemetry
        raw = record.raw
        if port in BYTES_PORTS and isinstance(exp.pattern, BytesPattern):
            letter, shown = f"{exp.entry.direction}{raw[:1].hex()}", raw.hex(" ").upper()
        elif isinstance(record, app.RECORDS):
            letter = record.letter
            shown = escape(raw) if raw else escape(app.encode(record))
        else:
            return
        if not self._active(exp):
            return  # what comes before the commands it answers is not an answer
        if not exp.align and now < self._time(exp) - exp.tolerance:
            if exp.strict:
                self._fail(exp, f"got {shown} at {now:.3f} s, too early (strict)")
            return
        if exp.pattern.matches(record):
            if exp.align:
                self.offset = now - exp.entry.time - self._lateness(exp)
            self.matched += 1
            self.closest.clear()
            return
        if exp.strict:
            self._fail(exp, f"got {shown} at {now:.3f} s instead (strict)")
            return
        distance = abs(now - self._time(exp))
        if letter not in self.closest or distance < self.closest[letter][0]:
            self.closest[letter] = (distance, f"{shown} at {now:.3f} s")

    def _time(self, exp: Expectation) -> float:
        """When the expectation is due: its time, shifted by the last @align match and by
        how late the `>` line before it went out."""
        return exp.entry.time + (0.0 if exp.align else self.offset) + self._lateness(exp)

    def _lateness(self, exp: Expectation) -> float:
        """How late the last `>` line before the expectation went out (0 before any)."""
        last = bisect.bisect_right(self.sends, exp.after, key=lambda e: e.time) - 1
        return self.late[last] if 0 <= last < len(self.late) else 0.0

    def active(self) -> bool:
        """An expectation is waiting and every `>` line before it has been sent."""
        return self.matched < len(self.expectations) and self._active(
            self.expectations[self.matched]
        )

    def _active(self, exp: Expectation) -> bool:
        """Every `>` line before the expectation has been sent."""
        return self.sent == len(self.sends) or self.sends[self.sent].time > exp.after

    def on_time(self, now: float) -> None:
        if self.done or self.matched >= len(self.expectations):
            return
        exp = self.expectations[self.matched]
        if now >= self._deadline(exp):
            key = exp.pattern.letter if isinstance(exp.pattern, Pattern) else None
            seen = self.closest.get(key) if key else next(iter(self.closest.values()), None)
            what = f"got {seen[1]} instead" if seen else f"no {exp.pattern.what} came"
            self._fail(exp, f"nothing matched by {self._deadline(exp):.3f} s; {what}")

    def _deadline(self, exp: Expectation) -> float:
        return self._time(exp) + exp.tolerance

    def _fail(self, exp: Expectation, what: str) -> None:
        self.failure = (
            f"{self.transcript.path}:{exp.entry.lineno}: expected {exp.pattern.text} at "
            f"{self._time(exp):.3f} s (±{exp.tolerance:g} s); {what}"
        )


def _expected(entry: Entry, path: str) -> Pattern | BytesPattern | None:
    """The expectation of a `<`, `2<` or `c<` line, or None when it expects nothing."""
    if PORT_OF[entry.direction] in BYTES_PORTS:
        hexed = uart2_bytes(entry.text)
        if hexed is not None:
            return BytesPattern(hexed[0], hexed[1], entry.text)
    try:
        return parse_pattern(entry.text)
    except InvalidValue as exc:
        raise AppmodeError(f"{path}:{entry.lineno}: {exc}") from None


def board_needs(args: tuple[str, ...], where: str) -> BoardNeeds:
    """`@board profile=minibalance drive=omni start=power-up` (each part optional; a
    user's profile file is named with its `digest=`)."""
    found: dict[str, str] = {}
    for arg in args:
        key, _, value = arg.partition("=")
        if key not in ("profile", "digest", "drive", "start") or key in found:
            raise AppmodeError(
                f"{where}: @board takes profile=…, digest=…, drive=… and start=power-up, "
                f"once each, not {arg!r}"
            )
        found[key] = value
    try:
        profile = recorded_profile(found.get("profile", "sheet"), found.get("digest"))
        drive = DriveType.from_cli_name(found["drive"]) if "drive" in found else None
        profile.check(drive=drive is not None, flash=False)
    except (AppmodeError, ValueError) as exc:
        raise AppmodeError(f"{where}: @board {exc}") from None
    if found.get("start", "power-up") != "power-up":
        raise AppmodeError(f"{where}: @board start= takes power-up, not {found['start']!r}")
    return BoardNeeds(profile, drive, "start" in found)
