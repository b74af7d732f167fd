"""A Foxglove layout for every shipped profile (issue 78.4): docs/foxglove/NAME.json is
what `appmode profile layout NAME` makes from the channel table (it cannot drift), and
every topic and field it names is one a board of that profile serves live; the 3D
panel is there where the profile's records say the car's pose."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path
from typing import Any

import pytest

from appmode.board.profiles import profile_named
from appmode.protocol.profile_file import SHIPPED
from appmode.protocol.sensed import Sensing
from appmode.viewers.layout import foxglove_layout
from tests.support.processes import ROOT, appmode_cmd, run

DOCS = ROOT / "docs" / "foxglove"


def placed(node: Any) -> set[str]:
    if isinstance(node, str):
        return {node}
    return placed(node["first"]) | placed(node["second"])


@pytest.mark.parametrize("name", SHIPPED)
def test_the_shipped_layout_is_the_one_the_command_makes(name: str) -> None:
    done = run("profile", "layout", name)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == foxglove_layout(profile_named(name).a_layout)
    assert (DOCS / f"{name}.json").read_text() == done.stdout


def _advertised(name: str) -> dict[str, dict[str, Any]]:
    """The channels a board of profile `name` serves live, by topic, schemas parsed."""
    pytest.importorskip("foxglove", reason="the foxglove extra is not installed")
    from tests.support.foxglove_client import watch_sync

    board = subprocess.Popen(
        appmode_cmd("board", "--profile", name, "--foxglove", "0", "--quiet"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        assert board.stderr is not None
        line = ""
        while "ws://" not in line:
            line = board.stderr.readline()
            assert line, "the board said no ws:// URL"
        url = re.search(r"ws://\S+", line)
        assert url is not None
        seen = watch_sync(url.group(0), 1.5, topics=set())
    finally:
        board.terminate()
        board.wait(10)
    return {
        topic: {**channel, "schema": json.loads(channel["schema"])}
        for topic, channel in seen.channels.items()
        if channel["schemaEncoding"] == "jsonschema"
    } | {t: c for t, c in seen.channels.items() if c["schemaEncoding"] != "jsonschema"}


@pytest.mark.parametrize("name", SHIPPED)
def test_every_topic_and_field_a_layout_names_is_served_live(name: str) -> None:
    layout = json.loads((DOCS / f"{name}.json").read_text())
    served = _advertised(name)
    config = layout["configById"]
    paths = [path["value"] for panel in config.values() for path in panel.get("paths", [])]
    assert len(paths) >= 8
    for path in paths:
        found = re.fullmatch(r"(/[\w/]+)\.(\w+)(\[\d+\])?", path)
        assert found, path
        topic, field = found.group(1), found.group(2)
        assert field in served[topic]["schema"]["properties"], (name, path)
    assert config["RosOut!log"]["topicToRender"] in served
    assert (
        config["Teleop!drive"]["topic"] == "/cmd_vel" and config["Teleop!drive"]["publishRate"] >= 5
    )
    scene = config.get("3D!pose")
    sensed = Sensing(profile_named(name).a_layout).gap is None or name.startswith("wheeltec")
    assert (scene is not None) == sensed
    if scene is not None:
        assert set(scene["topics"]) <= set(served) and {"/pose", "/tf"} <= set(served)
    assert placed(layout["layout"]) == set(config)


def test_a_layout_of_no_profile_is_one_line() -> None:
    done = run("profile", "layout", str(Path("no") / "such.toml"))
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
