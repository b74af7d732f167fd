"""A viewer that drives and tunes (issue 78.1, 78.2, 78.5): with `--foxglove-drive`, a
Teleop panel's twists on /cmd_vel drive the car through the stop authority, a
Parameters panel lists and sets the car's parameters; judged on the board's recording,
with a client written from the WebSocket protocol's description."""

from __future__ import annotations

import asyncio
import re
import subprocess
import time
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("foxglove", reason="the foxglove extra is not installed")
pytest.importorskip("websockets", reason="the test extra (websockets) is not installed")

from tests.support.foxglove_client import Driver, malformed, serving
from tests.support.processes import board_process, run, timed_sent

TWIST_LAPSE = 0.5


def driving(
    url: str, *extra: str, seconds: float = 8
) -> AbstractContextManager[tuple[subprocess.Popen[str], str]]:
    """`appmode drive URL --foxglove 0 --foxglove-drive` in script mode for `seconds`, and
    the ws:// URL it says."""
    return serving("drive", url, "--foxglove-drive", *extra, stdin=f"wait {seconds}\n")


def finish(proc: subprocess.Popen[str], early: bool = True) -> tuple[str, str]:
    """The session's end (`early`: ended now, by SIGTERM, rather than at its script's
    end): what it printed on stdout and stderr."""
    assert proc.stdout is not None and proc.stderr is not None
    if early:
        proc.terminate()
    out, err = proc.stdout.read(), proc.stderr.read()
    proc.wait(20)
    return out, err


async def _publish(driver: Driver, channel: int, x: float, seconds: float) -> float:
    """Twists of `x` m/s at 10 Hz for `seconds`; the time of the last one."""
    end = time.monotonic() + seconds
    last = time.monotonic()
    while time.monotonic() < end:
        await driver.twist(channel, x)
        last = time.monotonic()
        await asyncio.sleep(0.1)
    return last


def test_a_teleop_drives_the_car_and_its_lapse_stops_it(tmp_path: Path) -> None:
    record = tmp_path / "board.txt"
    with board_process("--record", str(record)) as board, driving(board.url) as (proc, url):

        async def teleop() -> tuple[float, dict[str, object]]:
            driver = await Driver.open(url)
            await driver.advertise(1)
            last = await _publish(driver, 1, 0.3, 2.0)
            await asyncio.sleep(1.0)  # the lapse stops it, not the viewer leaving
            await driver.close()
            return last, driver.info

        last, info = asyncio.run(teleop())
        out, _ = finish(proc)
    assert "clientPublish" in info["capabilities"]  # type: ignore[operator]
    assert info["supportedEncodings"] == ["json"]
    sent = timed_sent(record)
    start = next(t for t, p in sent if p == "A")
    stop = next(t for t, p in sent if p == "Z" and t > start)
    assert 1.8 <= stop - start <= 2.0 + TWIST_LAPSE + 0.3, sent
    assert board.clock_after + stop - last <= 0.8  # the board's Z within 0.8 s of the last
    assert "viewer 1 drives" in out and "no longer drives" in out


def test_one_viewer_drives_at_a_time_and_one_that_leaves_stops_the_car(tmp_path: Path) -> None:
    record = tmp_path / "board.txt"
    with board_process("--record", str(record)) as board, driving(board.url) as (proc, url):

        async def two() -> float:
            first, second = await Driver.open(url), await Driver.open(url)
            await first.advertise(1)
            await second.advertise(7)
            await _publish(first, 1, 0.3, 0.5)  # the first drives
            end = time.monotonic() + 1.0
            while time.monotonic() < end:
                await first.twist(1, 0.3)
                await second.twist(7, -0.3)  # backwards: never sent while the first drives
                await asyncio.sleep(0.1)
            await second.close()
            assert first.ws.transport is not None
            first.ws.transport.abort()  # killed: no unadvertise, no close
            left = time.monotonic()
            await asyncio.sleep(1.5)
            return left

        left = asyncio.run(two())
        out, _ = finish(proc)
    payloads = [p for _, p in timed_sent(record)]
    assert "A" in payloads and "E" not in payloads, payloads  # E: backwards
    assert "twists are refused: viewer" in out
    stop = next(t for t, p in timed_sent(record) if p == "Z")
    assert board.clock_after + stop - left <= 0.8


def test_the_parameters_panel_lists_sets_and_shows_a_refusal(tmp_path: Path) -> None:
    record = tmp_path / "board.txt"
    with board_process("--record", str(record)) as board, driving(board.url) as (proc, url):

        async def tune() -> tuple[dict[str, Any], dict[str, Any], list[dict[str, Any]]]:
            driver = await Driver.open(url)
            for attempt in range(40):  # the session reads them as it starts
                asked = f"get{attempt}"
                await driver.send({"op": "getParameters", "parameterNames": [], "id": asked})
                listed = await driver.wait_for(lambda m, asked=asked: m.get("id") == asked)
                if listed["parameters"]:
                    break
                await asyncio.sleep(0.2)
            names = [p["name"] for p in listed["parameters"]]
            await driver.send({"op": "subscribeParameterUpdates", "parameterNames": names})
            await driver.send(
                {
                    "op": "setParameters",
                    "parameters": [
                        {"name": "max_speed", "value": 800},
                        {"name": "max_speed", "value": 99999},  # out of range: refused
                    ],
                    "id": "set",
                }
            )
            answer = await driver.wait_for(lambda m: m.get("id") == "set")
            update = await driver.wait_for(  # when both sets are done: the values read back
                lambda m: (
                    m.get("op") == "parameterValues"
                    and "id" not in m
                    and {"name": "max_speed", "value": 800} in m["parameters"]
                ),
                seconds=8,
            )
            updates = [update]
            await driver.close()
            return listed, answer, updates

        listed, answer, updates = asyncio.run(tune())
        out, err = finish(proc)
    names = [p["name"] for p in listed["parameters"]]
    assert names[:2] == ["max_speed", "max_position"] and len(names) == 9
    assert answer["parameters"] == [{"name": "max_speed", "value": 500}]  # as it stood
    values = [{p["name"]: p["value"] for p in u["parameters"]} for u in updates]
    assert values[-1]["max_speed"] == 800  # read back; the refused one changed nothing
    assert "{0:800}" in [p for _, p in timed_sent(record)]
    assert "max_speed = 800 (verified)" in out
    assert re.search(r"appmode: error: max_speed = 99999 refused: .*must be in 0–65535", err), err


def test_garbage_and_a_killed_viewer_say_a_line_each_never_the_servers_log(
    tmp_path: Path,
) -> None:
    with board_process() as board, driving(board.url, seconds=4) as (proc, url):
        asyncio.run(malformed(url))
        out, err = finish(proc, early=False)
    assert proc.returncode == 0, err
    assert "Error receiving" not in err and "Invalid message" not in err, err
    assert "\x1b" not in out + err and "bogus0\\x1b[2J" in out  # shown escaped
    complaints = [line for line in out.splitlines() if line.startswith("foxglove: ")]
    assert 1 <= len(complaints) <= 3, out  # one of a kind, not one a message
    assert out.count("a /cmd_vel message was ignored") == 1, out


def test_driving_from_a_viewer_is_asked_for_and_this_machines_only() -> None:
    done = run("drive", "sim://", "--foxglove", "0.0.0.0:0", "--foxglove-drive")
    assert done.returncode == 2
    assert "--foxglove-drive serves this machine only" in done.stderr
    assert "ssh -L" in done.stderr and "Traceback" not in done.stderr
    done = run("drive", "sim://", "--foxglove-drive")
    assert done.returncode == 2 and "needs --foxglove PORT" in done.stderr


def test_without_foxglove_drive_a_viewer_cannot_drive_or_tune(tmp_path: Path) -> None:
    record = tmp_path / "board.txt"
    with (
        board_process("--record", str(record)) as board,
        serving("drive", board.url, stdin="wait 3\n") as (proc, url),
    ):

        async def try_it() -> dict[str, Any]:
            driver = await Driver.open(url)
            await driver.advertise(1)
            await _publish(driver, 1, 0.3, 1.0)
            await driver.send(
                {"op": "setParameters", "parameters": [{"name": "max_speed", "value": 800}]}
            )
            await asyncio.sleep(0.5)
            await driver.close()
            return driver.info

        info = asyncio.run(try_it())
        finish(proc)
    assert info["capabilities"] == []
    payloads = [p for _, p in timed_sent(record)]
    assert "A" not in payloads and "{0:800}" not in payloads, payloads
