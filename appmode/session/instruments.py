"""What a session shows, as values for instruments (a gauge, a dial, a slider) rather than
text: the page's components read these; the console's rows (`status.py`) are built from
the same link state and freshness rules, so both views say the same thing.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Literal

from appmode.host.app.state import HostState
from appmode.host.stats import LinkStats

LinkState = Literal["up", "late", "degraded", "lost", "opening", "silent"]
"""Up and fresh; up but the last record is over LATE old; errors in the last 5 s; the
link lost; open with nothing received yet; open and silent past SILENT."""
STALE = 0.5
"""Seconds without a record after which a reading shows how long it has been."""
LATE = 1.0
"""Seconds without a record after which the link itself is late."""
SILENT = 2.0
"""Seconds after opening with nothing received after which the link is called silent
(and the view says what to check)."""


@dataclass(frozen=True, slots=True)
class Link:
    """How a link is: its state, records a second, errors (all and in the last 5 s) and
    the age of its last record (None: nothing came)."""

    state: LinkState
    rate: float
    errors: int
    recent_errors: int
    age: float | None
    bytes_in: int
    bytes_out: int
    latency: float | None = None
    """Milliseconds a write took to reach a car shared over the network (None: a local
    link)."""


def link(connected: bool, stats: LinkStats, now: float, latency: float | None = None) -> Link:
    """The link's state from its counters: the one rule every view follows."""
    age = stats.since_last(now)
    recent = stats.recent_errors(now)
    state: LinkState
    if not connected:
        state = "lost"
    elif age is None:
        state = "opening" if now <= SILENT else "silent"
    elif recent:
        state = "degraded"
    else:
        state = "late" if age > LATE else "up"
    return Link(
        state, stats.rate(now), stats.errors, recent, age, stats.bytes_in, stats.bytes_out, latency
    )


@dataclass(frozen=True, slots=True)
class Telemetry:
    """The A and B records as numbers: the motion fields by their labels (and the A
    record's other fields with a unit: the balance car's angle), attitude in degrees,
    battery in percent; each None until its record came, and with its age. A profile
    whose B record is not the sheet's has it in `b`, by its fields' labels."""

    motion: tuple[tuple[str, int], ...] | None
    speed: float | None
    """The largest speed the motion fields show, in the board's velocity unit."""
    motion_age: float | None
    pitch: int | None
    roll: int | None
    yaw: int | None
    battery: int | None
    attitude_age: float | None
    b: tuple[tuple[str, int], ...] | None = None
    battery_age: float | None = None
    has_attitude: bool = True
    """Its B record is the sheet's (pitch, roll, yaw): a page draws the dials."""
    """The age of the record the battery came from (the B record's, or the A's)."""


def telemetry(state: HostState, now: float) -> Telemetry:
    layout, v, a = state.layout, state.velocity, state.attitude
    motion, speed, battery = None, None, None
    battery_age = state.velocities.age(now)  # until a B record gives it
    if v is not None:
        values, labels = v.values, layout.labels
        shown = [*layout.motion, *(i for i in layout.extra_a)]
        motion = tuple((labels[i], values[i]) for i in shown)
        speed = layout.speed(values)
        battery = None if layout.battery is None else values[layout.battery]
    b = None
    if not layout.sheet_b and state.attitudes.points:
        b_values = state.attitudes.points[-1][1].values
        b = tuple((f.label, value) for f, value in zip(layout.b_fields, b_values, strict=False))
        held = [value for f, value in zip(layout.b_fields, b_values, strict=False) if f.battery]
        if held:
            battery, battery_age = held[0], state.attitudes.age(now)
    elif a is not None:
        battery, battery_age = a.battery, state.attitudes.age(now)
    return Telemetry(
        motion,
        speed,
        state.velocities.age(now),
        None if a is None else a.pitch,
        None if a is None else a.roll,
        None if a is None else a.yaw,
        battery,
        state.attitudes.age(now),
        b,
        battery_age,
        layout.sheet_b,
    )


@dataclass(frozen=True, slots=True)
class Value:
    """A value a user sets (a parameter, a setting, the keys' speed): its name, what it
    is now (None: not read), its range, and whether it changed since it was last saved."""

    name: str
    value: int | None
    minimum: int
    maximum: int
    unsaved: bool = False
    scale: float = 1.0
    """The user's value is value / scale (a gain sent ×100: 100); minimum, maximum and
    value are the frame's integers."""


@dataclass(frozen=True, slots=True)
class Wheel:
    """One wheel of the control port's encoder report: target and actual speed."""

    name: str
    target: int
    actual: int


@dataclass(frozen=True, slots=True)
class Instruments:
    """Everything a page draws besides the key grid."""

    link: Link
    telemetry: Telemetry | None
    """The APP port's records (None: the session has no APP port)."""
    in_force: str
    """What drives the car, in words ("stopped" when nothing does): what it was last sent."""
    moving: bool
    stop_unsent: bool
    """The car was last sent motion and the link is down: no stop can reach it."""
    page: str | None
    """The app page the board is on (joystick, gravity, button), or None (UART2)."""
    speed: Value | None
    """What the speed keys change: max_speed on the APP port, the keys' speed on UART2;
    None: the profile has no speed parameter."""
    values: tuple[Value, ...]
    """The parameters (or settings) in the table's order."""
    values_read: bool
    wheels: tuple[Wheel, ...] | None
    """The encoder report, on the control port (None: off or not come)."""
    wheels_age: float | None
    driver: str | None
    """Who drives, on the control port: "UART2" once it took over, else "APP port"."""
    readings: tuple[tuple[str, str], ...] = ()
    """What the car reports in SI, by label, as text (a chassis port's status), with the
    age of the report in `readings_age`; none where its records say it (`telemetry`)."""
    readings_age: float | None = None
    volts: float | None = None
    """The battery's voltage, where the car reports it so (no percentage is made up)."""


def values(
    table: Sequence[tuple[str, int, int]],
    now: dict[str, int],
    unsaved: Collection[str],
    scales: Sequence[float] = (),
) -> tuple[Value, ...]:
    """Each (name, minimum, maximum) of a table with its value now (None: not read),
    whether it is among the unsaved, and its scale (1 unless given)."""
    scale = [*scales, *[1.0] * (len(table) - len(scales))]
    return tuple(
        Value(name, now.get(name), low, high, name in unsaved, s)
        for (name, low, high), s in zip(table, scale, strict=True)
    )
