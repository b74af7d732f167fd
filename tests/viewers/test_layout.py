"""The Foxglove layout in docs names only channels and fields appmode serves (issue
68.4): every plotted path is a channel of `protocol.channels` or of the live view, and
a field its JSON schema lists; every panel is placed, and every placed panel set up."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from appmode.protocol.channels import channels
from appmode.protocol.layouts import VELOCITY
from appmode.viewers.live import LOG

LAYOUT = Path(__file__).resolve().parents[2] / "docs" / "foxglove" / "appmode-layout.json"


def placed(node: Any) -> set[str]:
    if isinstance(node, str):
        return {node}
    return placed(node["first"]) | placed(node["second"])


def test_every_path_is_a_field_appmode_serves() -> None:
    layout = json.loads(LAYOUT.read_text())
    schemas = {topic: spec.schema for topic, spec in channels(VELOCITY).items()}
    paths = [
        path["value"]
        for config in layout["configById"].values()
        for path in config.get("paths", [])
    ]
    assert len(paths) >= 10
    for path in paths:
        found = re.fullmatch(r"(/[\w/]+)\.(\w+)(\[\d+\])?", path)
        assert found, path
        topic, field = found.group(1), found.group(2)
        assert field in schemas[topic]["properties"], path
    assert layout["configById"]["RosOut!log"]["topicToRender"] == LOG
    assert "/pose" in layout["configById"]["3D!path"]["topics"]
    assert placed(layout["layout"]) == set(layout["configById"])
