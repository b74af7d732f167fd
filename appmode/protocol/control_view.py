"""Views of the control port's events (docs/protocol.md §8–§12): JSON and one-line text;
`view` shows an event of either port."""

from __future__ import annotations

from typing import Any

from appmode.protocol import app, chassis, control, render, settings
from appmode.protocol.layouts import VELOCITY, Layout

EVENTS = (
    control.VelocityFrame,
    control.MotorFrame,
    control.PositionFrame,
    control.SetSetting,
    control.StoreFrame,
    control.ReadFrame,
    control.Reply,
    control.EncoderReport,
    control.Status,
    control.BadFrame,
    control.Garbage,
)
"""The control port's event types: what these views show."""
BoardOrHost = control.HostEvent | control.Reply | control.EncoderReport | control.Status
"""An event of either direction that these views show."""
KINDS = dict(
    zip(
        EVENTS,
        (
            "velocity_frame",
            "motor_frame",
            "position_frame",
            "set_setting",
            "store",
            "read",
            "reply",
            "encoder_report",
            "status",
            "bad_frame",
            "garbage",
        ),
        strict=True,
    )
)


def hex_text(raw: bytes) -> str:
    return raw.hex(" ").upper()


def to_json(event: BoardOrHost) -> dict[str, Any]:
    """One JSON-ready object: `kind`, its values, and `raw` as hex pairs."""
    body: dict[str, Any] = {"kind": KINDS[type(event)]}
    if isinstance(event, control.VelocityFrame):
        body.update(a=event.a, b=event.b, c=event.c, angle=event.angle)
    elif isinstance(event, control.MotorFrame):
        body["speeds"] = list(event.speeds)
    elif isinstance(event, control.PositionFrame):
        body.update(x=event.x, y=event.y, z=event.z)
    elif isinstance(event, control.SetSetting):
        body.update(name=event.setting.name, value=event.value)
    elif isinstance(event, control.StoreFrame):
        body["op"] = event.op.name
    elif isinstance(event, control.ReadFrame):
        body["name"] = event.read.name
    elif isinstance(event, control.Reply):
        body.update(name=event.name, value=event.value)
    elif isinstance(event, control.EncoderReport):
        body.update(targets=list(event.targets), actuals=list(event.actuals))
    elif not isinstance(event, control.Status):
        body["reason"] = event.reason
    return {**body, "raw": hex_text(event.raw)}


def describe(event: BoardOrHost) -> str:
    """A short human description."""
    if isinstance(event, control.VelocityFrame):
        what = f"velocity {event.a} {event.b} {event.c}"
        return f"{what} (angle mode: {event.c / 10:g}°)" if event.angle else what
    if isinstance(event, control.MotorFrame):
        return "motors " + " ".join(map(str, event.speeds))
    if isinstance(event, control.PositionFrame):
        return f"position x={event.x} y={event.y} z={event.z}"
    if isinstance(event, control.SetSetting):
        return f"set {event.setting.name} = {event.value}"
    if isinstance(event, control.StoreFrame):
        return event.op.meaning
    if isinstance(event, control.ReadFrame):
        return f"read {event.read.name}"
    if isinstance(event, control.Reply):
        return f"reply {event.name} = {event.value}"
    if isinstance(event, control.EncoderReport):
        pairs = zip("ABCD", event.targets, event.actuals, strict=False)
        return "encoders " + " ".join(f"{w}={t}/{a}" for w, t, a in pairs)
    if isinstance(event, control.Status):
        return "the firmware's status burst (§13.1)"
    return f"error: {event.reason}"


def settings_table(values: dict[str, int]) -> str:
    """The ten settings as an aligned table (docs/protocol.md §10): id, name, value,
    range, default; a value outside its range (a board may hold one) is flagged."""
    rows = [f"{'SS':>2}  {'name':<18} {'value':>10}  {'range':<14} {'default':>7}"]
    for setting in settings.SETTINGS:
        value = values[setting.name]
        flag = "" if settings.value_error(setting, value) is None else "  out of range"
        rows.append(
            f"{setting.id:>2}  {setting.name:<18} {value:>10}  "
            f"{setting.range_text:<14} {setting.default:>7}{flag}"
        )
    return "\n".join(rows)


def view(
    event: app.Event | control.HostEvent | control.BoardEvent | chassis.Event,
    layout: Layout = VELOCITY,
) -> tuple[dict[str, Any], str, str | None]:
    """An event of any port for people and machines: its JSON body, its description,
    and how to show its bytes (hex pairs on UART2 and a chassis port; None: escaped
    text)."""
    if isinstance(event, (chassis.Command, chassis.Status, chassis.Junk)):
        return chassis.as_json(event), str(event), event.raw.hex(" ").upper()
    if isinstance(event, EVENTS):
        shown = hex_text(event.raw)
        return to_json(event), describe(event), shown
    return render.to_json(event, layout), render.describe(event, layout), None
