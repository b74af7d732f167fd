"""What the chassis port's session shows: the link, what is in force and how it is held,
and the status frames in SI — velocity, IMU, battery, Flag_Stop."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from appmode.session import instruments
from appmode.session.instruments import Instruments, Value
from appmode.session.rows import Row, Span, Tone, link_rows, reading, unsent_row

if TYPE_CHECKING:
    from appmode.host.chassis.client import ChassisHost

SILENT_HINT = (
    "a chassis sends a status frame every 50 ms: check the cable and that the car is on; "
    "appmode doctor finds its port"
)
STOP = "stop"
LOW_VOLTS = 10.5
"""Volts under which a WHEELTEC car's 3S battery is low (its firmware warns at 10 V)."""


@dataclass(frozen=True, slots=True)
class Keys:
    """What the session holds that its status shows: the motion its keys drive (or
    `stop`), the keys' speed in mm/s, how keys hold, whether anything is in force."""

    in_force: str
    speed: int
    top_speed: int
    hold: str
    moving: bool


def in_force_text(host: ChassisHost, keys: Keys) -> str:
    if keys.in_force != STOP:
        return keys.in_force
    return host.in_force_text() or "stopped"


def chassis_rows(host: ChassisHost, keys: Keys) -> list[Row]:
    state = host.state
    now = host.now()
    rows = link_rows(
        host.connected, state.stats, now, "status frames", SILENT_HINT, latency=host.latency
    )
    spec = host.profile.chassis
    kind = "" if spec is None else f" · {spec.kind} · resent every 0.1 s while it drives"
    rows.append(Row("chassis", (("", f" {host.profile.name}{kind}"),)))
    text = in_force_text(host, keys)
    if keys.moving and not host.connected:
        rows += [Row("in force", (("alert", f" {text} "),)), unsent_row()]
    else:
        what: Span = ("", " stopped") if text == "stopped" else ("on", f" {text} ")
        shown = f"   speed {keys.speed / 1000:.2f} m/s · {keys.hold}"
        rows.append(Row("in force", (what, ("", shown))))
    status, at = state.status, state.status_at
    age = None if at is None else now - at
    if status is None:
        return [*rows, Row("velocity", (("", "  —"),)), Row("battery", (("", "  —"),))]
    twist = status.twist
    flag: list[Span] = [("warn", " Flag_Stop: booting or stopped by the board ")]
    velocity = reading("velocity", f"{twist}", age)
    ax, ay, az = status.acceleration
    gx, gy, gz = status.angular_velocity
    imu = f"accel {ax:+.2f} {ay:+.2f} {az:+.2f} m/s²   gyro {gx:+.3f} {gy:+.3f} {gz:+.3f} rad/s"
    rows += [velocity, reading("imu", imu, age)]
    tone: Tone = (
        "dim"
        if age is not None and age > instruments.STALE
        else ("low" if status.volts < LOW_VOLTS else "ok")
    )
    rows.append(Row("battery", ((tone, f" {status.volts:5.2f} V"),)))
    if status.flag_stop:
        rows.append(Row("", tuple(flag)))
    return rows


def chassis_instruments(host: ChassisHost, keys: Keys) -> Instruments:
    """What the page's instruments show over the chassis port: its status in SI."""
    state = host.state
    status, at = state.status, state.status_at
    readings: tuple[tuple[str, str], ...] = ()
    if status is not None:
        twist = status.twist
        ax, ay, _ = status.acceleration
        readings = (
            ("forward", f"{twist.forward:+.2f} m/s"),
            ("left", f"{twist.left:+.2f} m/s"),
            ("turn", f"{twist.turn:+.2f} rad/s"),
            ("accel", f"{ax:+.2f} {ay:+.2f} m/s²"),
            ("gyro z", f"{status.angular_velocity[2]:+.3f} rad/s"),
            *((("Flag_Stop", "set"),) if status.flag_stop else ()),
        )
    return Instruments(
        link=instruments.link(host.connected, state.stats, host.now(), host.latency),
        telemetry=None,
        in_force=in_force_text(host, keys),
        moving=keys.moving,
        stop_unsent=keys.moving and not host.connected,
        page=None,
        speed=Value("speed mm/s", keys.speed, 0, keys.top_speed),
        values=(),
        values_read=True,
        wheels=None,
        wheels_age=None,
        driver="chassis port",
        readings=readings,
        readings_age=None if at is None else host.now() - at,
        volts=None if status is None else status.volts,
    )
