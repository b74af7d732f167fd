"""`appmode web --fleet` (issue 66.5): the cars a key opens as cards, a car chosen there
driven on the usual page, and the stop-all with each car's confirmation — two cars
shared on loopback, each judged on its board's own recording."""

from __future__ import annotations

import asyncio
import json
import re
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import aiohttp
import pytest

from tests.support.processes import appmode_cmd, serving, stop_process, wait_for
from tests.support.shares import KEY, SharedBoard, shared_board

pytest.importorskip("zenoh", reason="the net extra (eclipse-zenoh) is not installed")


@pytest.fixture
def fleet(tmp_path: Path) -> Iterator[tuple[SharedBoard, SharedBoard, subprocess.Popen[str], str]]:
    with (
        shared_board(tmp_path, "car-a") as first,
        shared_board(tmp_path, "car-b", "--connect", first.endpoint) as second,
    ):
        web, line = serving(
            "web",
            "--fleet",
            "--connect",
            first.endpoint,
            "--fleet-key",
            KEY,
            "--listen",
            "127.0.0.1:0",
            data=tmp_path / "data",
        )
        found = re.match(r"web: (http://\S+)", line)
        try:
            assert found, f"web printed {line!r}: {stop_process(web)}"
            yield first, second, web, found.group(1)
        finally:
            stop_process(web)


async def receive(socket: aiohttp.ClientWebSocketResponse, kind: str) -> dict[str, Any]:
    while True:
        message = json.loads((await socket.receive(timeout=10)).data)
        if message["t"] == kind:
            return message


async def cards(socket: aiohttp.ClientWebSocketResponse, count: int) -> list[dict[str, Any]]:
    """The cards once `count` cars answer."""
    end = time.monotonic() + 15
    while time.monotonic() < end:
        shown = (await receive(socket, "fleet"))["cars"]
        if len(shown) >= count:
            return list(shown)
    raise AssertionError("the cars did not answer in 15 s")


def test_the_fleet_page_shows_the_cars_drives_one_and_stops_them_all(
    fleet: tuple[SharedBoard, SharedBoard, subprocess.Popen[str], str],
) -> None:
    first, second, web, address = fleet
    origin = address.split("/?", 1)[0]
    host = origin.split("//", 1)[1]
    headers = {"Cookie": f"appmode_token={address.rsplit('=', 1)[1]}", "Origin": origin}

    async def scenario() -> dict[str, Any]:
        async with aiohttp.ClientSession() as client:
            async with client.get(f"{origin}/", headers=headers) as index:
                assert index.status == 200 and "appmode fleet" in await index.text()
            async with client.get(f"{origin}/", headers={"Origin": origin}) as stranger:
                assert stranger.status == 403
            socket = await client.ws_connect(f"ws://{host}/fleet/ws", headers=headers)
            shown = await cards(socket, 2)
            assert [car["name"] for car in shown] == ["car-a", "car-b"]
            assert all(car["battery"] is not None and car["in_force"] is None for car in shown)
            for bad in ("nosuch", "..%2Fetc", "car-b%00"):
                async with client.get(f"{origin}/car/{bad}", headers=headers) as refused:
                    assert refused.status == 404, bad
            async with client.get(f"{origin}/car/car-b", headers=headers) as chosen:
                assert chosen.status == 200 and 'id="fleet-link"' in await chosen.text()
            page = await client.ws_connect(f"ws://{host}/ws", headers=headers)
            status = await receive(page, "status")
            assert status["fleet"] == "car-b" and status["url"].endswith("key=…")
            deadline = time.monotonic() + 10
            await page.send_str(json.dumps({"t": "press", "key": "forward"}))
            while "A" not in second.sent() and time.monotonic() < deadline:
                await page.send_str(json.dumps({"t": "hold", "key": "forward"}))
                await asyncio.sleep(0.05)
            assert "A" in second.sent() and "A" not in first.sent()
            driven = [car for car in await cards(socket, 2) if car["in_force"]]
            while not driven and time.monotonic() < deadline:
                await page.send_str(json.dumps({"t": "hold", "key": "forward"}))
                driven = [car for car in await cards(socket, 2) if car["in_force"]]
            assert [car["name"] for car in driven] == ["car-b"], driven
            await socket.send_str(json.dumps({"t": "stop_all"}))
            stopped = await receive(socket, "stopped")
            await page.close()
            await socket.close()
            return stopped

    stopped = asyncio.run(scenario())
    answers = {answer["name"]: answer for answer in stopped["answers"]}
    assert set(answers) == {"car-a", "car-b"}
    assert all(answer["sent"] and answer["confirmed"] for answer in answers.values()), answers
    wait_for(lambda: second.sent()[-1] == "Z", 5)
    err = stop_process(web)
    assert web.returncode == 0 and "Traceback" not in err, err
    assert second.sent()[-1] == "Z" and "A" not in first.sent()


def test_a_moving_car_whose_host_vanished_keeps_its_card(
    fleet: tuple[SharedBoard, SharedBoard, subprocess.Popen[str], str],
) -> None:
    """Issue 80.7: the fleet page dropped the card of a moving car whose share died (no
    card for ~7 s while the board drove on), and nothing said it might still be moving."""
    _, second, _, address = fleet
    origin = address.split("/?", 1)[0]
    host = origin.split("//", 1)[1]
    headers = {"Cookie": f"appmode_token={address.rsplit('=', 1)[1]}", "Origin": origin}
    driver = subprocess.Popen(
        appmode_cmd("drive", second.url), stdin=subprocess.PIPE, text=True,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    assert driver.stdin is not None
    driver.stdin.write("drive A\nwait 60\n")
    driver.stdin.flush()

    async def scenario() -> list[dict[str, Any]]:
        async with aiohttp.ClientSession() as client:
            socket = await client.ws_connect(f"ws://{host}/fleet/ws", headers=headers)
            deadline = time.monotonic() + 15
            while time.monotonic() < deadline:
                shown = await cards(socket, 2)
                if any(car["name"] == "car-b" and car["in_force"] for car in shown):
                    break
            second.share.kill()  # its host dies with the car moving
            seen = []
            end = time.monotonic() + 5  # five seconds of the page's cards (each as it
            while time.monotonic() < end:  # changes: a look a second)
                seen.append(await receive(socket, "fleet"))
            await socket.close()
            return seen

    try:
        seen = asyncio.run(scenario())
    finally:
        driver.kill()
        driver.communicate()
    last = {car["name"]: car for car in seen[-1]["cars"]}
    assert "car-b" in last, "the moving car's card is gone"
    assert "may still be moving" in last["car-b"]["in_force"], last["car-b"]
    assert all("car-b" in {car["name"] for car in message["cars"]} for message in seen)
    assert second.sent()[-1] == "A", "the board's own recording: still driving"
