"""The page and the conformance suite over `ble://` and `bt://`, judged on the board's
recording."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import aiohttp
import pytest

from appmode.testing.served import ServedBoard
from tests.bluetooth.test_standin import kill_bus
from tests.support.processes import run
from tests.support.web import WebProcess, wait_sent, web_process
from tests.web.test_server import beat_until_sent, page, ready, status

SUITE = Path(__file__).resolve().parents[2] / "transcripts" / "suite"
SOME = ("s2_2_read_params", "s2_2_q_separator", "s5_save")
"""Short transcripts: the real-time suite's windows (±0.25 s) over the modelled radio, a
few seconds each; the whole suite over ble:// passes too (12 of 12, 109 s)."""


async def shown_while_held(socket: Any, seconds: float = 6.0) -> dict[str, float]:
    """What the page is told while forward is held (beating as a page does): the link's
    records a second and the y velocity, once both are the board's (the stream at its
    rate, y 500), or as they last were."""
    end = asyncio.get_running_loop().time() + seconds
    seen: dict[str, float] = {}
    while asyncio.get_running_loop().time() < end:
        await socket.send_json({"t": "hold", "key": "forward"})
        shown = await status(socket)
        ins = shown["instruments"]
        motion = dict(ins["telemetry"]["motion"] or ())
        seen = {"rate": ins["link"]["rate"], "y": motion.get("y (forward +)", motion.get("y", 0))}
        if seen["rate"] >= 15 and seen["y"] == 500:
            break
    return seen


@pytest.mark.parametrize("which", ["ble", "spp"])
def test_the_page_drives_the_car_over_the_module(tmp_path: Path, which: str) -> None:
    async def scenario(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            await socket.send_json({"t": "press", "key": "forward"})
            await beat_until_sent(socket, web, "A")
            seen = await shown_while_held(socket)
            assert seen["rate"] >= 15 and seen["y"] == 500, seen  # issue 69.1
            await socket.send_json({"t": "release"})
            wait_sent(web, "Z")
            await socket.send_json({"t": "press", "key": "left"})
            await beat_until_sent(socket, web, "G")
            await socket.close()  # a closed page stops the car
            wait_sent(web, "Z")

    with web_process(tmp_path, bluetooth=which) as web:
        assert web.board.url.startswith("ble://" if which == "ble" else "bt://")
        asyncio.run(scenario(web))
    assert web.sent()[-1] == "Z"


@pytest.mark.alone
@pytest.mark.parametrize("which", ["ble", "spp"])
def test_conform_passes_over_the_module(appmode_ble_board: ServedBoard, which: str) -> None:
    url = getattr(appmode_ble_board, which)
    files = [str(SUITE / f"{name}.transcript") for name in SOME]
    done = run("conform", "--board", url, "--yes", *files, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"{len(SOME)} passed, 0 failed" in done.stdout
    sent = [e.data for e in appmode_ble_board.recording().entries if e.direction == ">"]
    assert sent[-1] == b"Z", sent[-5:]


def test_a_module_gone_for_good_the_page_and_the_exit_say_the_car_may_be_moving(
    tmp_path: Path,
) -> None:
    """Issue 64.2: no stop can reach the car; the page never shows one, and the server
    ends non-zero saying so."""

    async def scenario(web: WebProcess) -> dict[str, Any]:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            await socket.send_json({"t": "press", "key": "forward"})
            await beat_until_sent(socket, web, "A")
            kill_bus(web.board.details["bus"])
            deadline = asyncio.get_running_loop().time() + 15
            while True:
                await socket.send_json({"t": "hold", "key": "forward"})
                shown = await status(socket)
                if shown["instruments"]["stop_unsent"]:
                    return shown
                assert asyncio.get_running_loop().time() < deadline, shown["messages"]

    with web_process(tmp_path, bluetooth="ble") as web:
        shown = asyncio.run(scenario(web))
        code, err = web.stop()
    assert shown["instruments"]["moving"] and shown["instruments"]["in_force"] != "stopped"
    assert any("NOT STOPPED" in span[1] for row in shown["rows"] for span in row["spans"])
    assert code == 1, err
    assert "the final stop was not delivered: the car may still be moving" in err, err
    assert web.sent()[-1] == "A", "the board's own recording: nothing stopped it"
