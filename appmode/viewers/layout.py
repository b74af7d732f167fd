"""A Foxglove layout for a profile (`appmode profile layout NAME`), made from the channel
table (`protocol.channels`), so that it names only topics and fields the live view and
the recordings carry for that profile: its records plotted by their own field names,
the chassis port's status where the board has one, the encoders, the command in force,
the log, the car's pose where its records say it (`protocol.sensed`), and the Teleop
(/cmd_vel, 10 Hz) and Parameters panels that `--foxglove-drive` serves."""

from __future__ import annotations

from typing import Any

from appmode.protocol.channels import CMD_VEL, IN_FORCE, LOG, channels
from appmode.protocol.layouts import Layout
from appmode.protocol.sensed import Sensing

TELEOP_RATE = 10
"""Twists a second the Teleop panel sends (each lasts 0.5 s: `session.desk`)."""
SPEED, TURN = 0.3, 0.5
"""What the Teleop panel's buttons drive: m/s, rad/s."""


def foxglove_layout(layout: Layout) -> dict[str, Any]:
    """The layout (Foxglove's and Lichtblick's JSON: Layouts → Import from file)."""
    specs = channels(layout)
    chassis = layout.profile.chassis is not None
    motion = [f.name for f in layout.a_fields]
    panels: dict[str, dict[str, Any]] = {
        "Plot!motion": _plot("A records (the profile's units)", "/app/A", motion),
        "Plot!attitude": _plot("B records", "/app/B", [f.name for f in layout.b_fields]),
        "Plot!encoders": _plot(
            "encoders (the control port's reports)",
            "/uart2/encoders",
            ["actuals[0]", "actuals[1]", "targets[0]", "targets[1]"],
        ),
    }
    if chassis:
        fields = ["forward", "left", "turn", "volts"]
        panels["Plot!chassis"] = _plot("chassis status (SI)", "/chassis/status", fields)
    panels["StateTransitions!inforce"] = {
        "paths": [
            {"value": f"{IN_FORCE}.command", "timestampMethod": "receiveTime"},
            {"value": f"{IN_FORCE}.moving", "timestampMethod": "receiveTime"},
        ],
        "isSynced": True,
    }
    panels["RosOut!log"] = {"topicToRender": LOG, "searchTerms": [], "minLogLevel": 1}
    if chassis or Sensing(layout).gap is None:
        panels["3D!pose"] = _scene()
    panels["Teleop!drive"] = _teleop()
    panels["Parameters!car"] = {"title": "parameters (--foxglove-drive)"}
    for key, panel in panels.items():
        for path in panel.get("paths", []):
            topic, _, field = path["value"].partition(".")
            assert field.split("[")[0] in specs[topic].schema["properties"], (key, path)
    return {
        "configById": panels,
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1},
        "layout": _arranged(list(panels)),
    }


def _plot(title: str, topic: str, fields: list[str]) -> dict[str, Any]:
    paths = [
        {"value": f"{topic}.{field}", "enabled": True, "timestampMethod": "receiveTime"}
        for field in fields
    ]
    return {
        "title": title,
        "paths": paths,
        "showLegend": True,
        "isSynced": True,
        "xAxisVal": "timestamp",
    }


def _scene() -> dict[str, Any]:
    return {
        "followMode": "follow-pose",
        "followTf": "base_link",
        "scene": {"transforms": {"showLabel": True}},
        "topics": {"/pose": {"visible": True, "type": "arrow"}},
        "transforms": {"frame:odom": {"visible": True}, "frame:base_link": {"visible": True}},
    }


def _teleop() -> dict[str, Any]:
    def button(field: str, value: float) -> dict[str, Any]:
        return {"field": field, "value": value}

    return {
        "topic": CMD_VEL,
        "publishRate": TELEOP_RATE,
        "upButton": button("linear-x", SPEED),
        "downButton": button("linear-x", -SPEED),
        "leftButton": button("angular-z", TURN),
        "rightButton": button("angular-z", -TURN),
    }


def _arranged(keys: list[str]) -> dict[str, Any] | str:
    """The panels in two columns, plots on the left, each column split evenly."""
    plots = [k for k in keys if k.startswith("Plot!")]
    rest = [k for k in keys if k not in plots]
    return {
        "direction": "row",
        "first": _column(plots),
        "second": _column(rest),
        "splitPercentage": 50,
    }


def _column(keys: list[str]) -> dict[str, Any] | str:
    if len(keys) == 1:
        return keys[0]
    return {
        "direction": "column",
        "first": keys[0],
        "second": _column(keys[1:]),
        "splitPercentage": 100 / len(keys),
    }
