"""Which firmware of the family a board runs, from what it sends: `appmode doctor`'s
judgement, against the shipped profiles' files.

Each profile is held to what was heard: the field count of each record kind, the
values its fields may take (a magnitude is never negative, a wrapped field stays under
its wrap, a battery is at most 100 % and the same in the A and B records when both
carry it), the record period (when the records came evenly), the start-up text
(`boot`) and the extra replies (`##$`). A profile that something heard contradicts is
out; among the rest the one with the most positive evidence wins (the order of
`SHIPPED` breaks a tie). The period only counts against a profile when it is far off,
and not at all when the records came in bursts (a loaded host delivers them late).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import NamedTuple

from appmode.protocol import profile_file
from appmode.protocol.profile_file import Field, ProfileFile

SHOWN = 64
"""Records kept of what a port sent, for the judgement."""
PERIOD_FITS = (0.9, 1.1)
"""A measured period within these fractions of a profile's range is evidence for it."""
PERIOD_FAR = (0.6, 1.5)
"""Outside these, against it."""
BATTERY_AGREES = 3
"""Percent by which the A and B records' battery readings may differ (read apart)."""


class Sent(NamedTuple):
    """What a port sent: its records (letter and values, as many fields as came), the
    mean record period, the text outside records."""

    records: Sequence[tuple[str, tuple[int, ...]]]
    period_ms: float | None
    text: bytes
    steady: bool = True
    """The records came evenly (no burst of late ones: a loaded host's), so that the
    period says something."""


class Judgement(NamedTuple):
    profile: ProfileFile
    score: int
    against: tuple[str, ...]
    """What was heard that this profile contradicts; empty: it fits."""


def judge(sent: Sent, profiles: Sequence[ProfileFile] | None = None) -> list[Judgement]:
    """Each profile's fit, the best first (those that fit before those that do not)."""
    profiles = profiles or [profile_file.shipped(name) for name in profile_file.SHIPPED]
    found = [_judge(profile, sent) for profile in profiles]
    order = {id(j): i for i, j in enumerate(found)}
    return sorted(found, key=lambda j: (bool(j.against), len(j.against), -j.score, order[id(j)]))


def best(sent: Sent) -> tuple[ProfileFile | None, Judgement]:
    """The profile that fits best (None when none does) and the nearest judgement."""
    first = judge(sent)[0]
    return (None if first.against else first.profile), first


def _judge(profile: ProfileFile, sent: Sent) -> Judgement:
    against: list[str] = []
    score = 0
    by_kind = {"A": profile.a, "B": profile.b}
    columns: dict[str, list[tuple[int, ...]]] = {"A": [], "B": []}
    readings: list[tuple[str, int]] = []  # the battery, in the order the records came
    for letter, values in sent.records:
        fields = by_kind.get(letter)
        if letter == "C" and len(values) != len(profile.params):
            against.append(f"C records of {len(values)} fields ({len(profile.params)} here)")
        if fields is None:
            continue
        if len(values) != len(fields):
            against.append(f"{letter} records of {len(values)} fields ({len(fields)} here)")
            continue
        columns[letter].append(values)
        held = [v for f, v in zip(fields, values, strict=True) if f.battery]
        readings += [(letter, held[0])] if held else []
    if columns["B"]:
        score += 1  # its B records have this profile's field count
    for letter, rows in columns.items():
        for i, field in enumerate(by_kind[letter]):
            problem = _field_problem(field, [row[i] for row in rows])
            if problem:
                against.append(f"{letter} field {i + 1} {problem} ({field.name} here)")
    score += _battery_evidence(readings, against)
    score += _period_evidence(profile, sent.period_ms if sent.steady else None, against)
    if profile.boot and profile.boot.encode() in sent.text:
        score += 3
    for reply in profile.replies:
        if reply.encode() in sent.text:
            score += 2
    if b"##$" in sent.text and "##$" not in profile.replies:
        against.append("it sends ##$ before its C record (this firmware does not)")
    return Judgement(profile, score, tuple(dict.fromkeys(against)))


def _field_problem(field: Field, column: list[int]) -> str:
    if not column:
        return ""
    if not field.signed and min(column) < 0:
        return f"is negative ({min(column)}): a magnitude"
    if field.wrap is not None and max(column) >= field.wrap:
        return f"reaches {max(column)}: it wraps at {field.wrap}"
    if field.battery and max(column) > 100:  # below 0: a board reading 0 V (§13.1)
        return f"reads {max(column)}: a battery percentage"
    return ""


def _battery_evidence(readings: list[tuple[str, int]], against: list[str]) -> int:
    """The battery readings in the order they came: where the A and B records both carry
    it, neighbours must mostly agree (the level may change between two, as when a board's
    motors come on) and agreeing on a charge is evidence; one record's battery that reads
    as one, steadily, is some."""
    pairs = [(x, y) for (first, x), (second, y) in itertools.pairwise(readings) if first != second]
    if pairs:
        agree = [x for x, y in pairs if abs(x - y) <= BATTERY_AGREES]
        if 2 * len(agree) < len(pairs):
            x, y = pairs[-1]
            against.append(f"its A and B records' battery fields differ ({x}, {y})")
            return 0
        return 2 if max(agree) > 0 else 0
    values = [value for _, value in readings]
    steady = values and min(values) > 0 and max(values) - min(values) <= BATTERY_AGREES
    return 1 if steady else 0


def _period_evidence(profile: ProfileFile, period: float | None, against: list[str]) -> int:
    if period is None:
        return 0
    low, high = profile.period_ms
    if low * PERIOD_FITS[0] <= period <= high * PERIOD_FITS[1]:
        return 1
    if not low * PERIOD_FAR[0] <= period <= high * PERIOD_FAR[1]:
        against.append(f"a record every {period:.0f} ms ({low}–{high} ms here)")
    return 0
