"""`appmode web` end to end: who may come in, and that the car stops whatever ends a
direction — release, silence, a closed page, a second page taking over, the server's end."""

from __future__ import annotations

import asyncio
import json
import signal
import ssl
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any

import aiohttp

from tests.support.web import WebProcess, wait_frame, wait_frames, wait_sent, web_process


def get(
    url: str, headers: dict[str, str] | None = None, tls: ssl.SSLContext | None = None
) -> tuple[int, dict[str, str], str]:
    """GET without following redirects (over `tls` for https): status, headers, body."""

    class NoRedirect(urllib.request.HTTPRedirectHandler):
        def redirect_request(self, *args: Any) -> None:
            return None

    opener = urllib.request.build_opener(NoRedirect, urllib.request.HTTPSHandler(context=tls))
    request = urllib.request.Request(url, headers=headers or {})
    try:
        with opener.open(request, timeout=5) as response:
            return response.status, dict(response.headers), response.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, dict(error.headers), error.read().decode()


def cookie(web: WebProcess) -> dict[str, str]:
    return {"Cookie": f"appmode_token={web.token}"}


async def page(
    session: aiohttp.ClientSession, web: WebProcess, origin: str | None = None
) -> aiohttp.ClientWebSocketResponse:
    host = web.origin.split("//", 1)[1]
    return await session.ws_connect(
        f"ws://{host}/ws", headers={**cookie(web), "Origin": origin or web.origin}
    )


async def status(socket: aiohttp.ClientWebSocketResponse) -> dict[str, Any]:
    while True:
        message = json.loads((await socket.receive(timeout=5)).data)
        if message["t"] == "status":
            return message


async def ready(
    socket: aiohttp.ClientWebSocketResponse, said: str = "parameters read", timeout: float = 20
) -> dict[str, Any]:
    """The first status after the session read the board's parameters (or said `said`);
    AssertionError with what it said instead after `timeout` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        shown = await status(socket)
        if said in shown["messages"]:
            return shown
        assert time.monotonic() < deadline, f"no {said!r} in {timeout:g} s: {shown['messages']}"


async def beat_until_sent(
    socket: aiohttp.ClientWebSocketResponse, web: WebProcess, wanted: str, timeout: float = 5.0
) -> None:
    """Wait until the board has received `wanted` last, beating meanwhile as a page does
    (a page that went quiet for the 0.25-s lease while a loaded machine was slow to show
    the board's recording would have had its car stopped, rightly)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        sent = web.sent()
        if sent and sent[-1] == wanted:
            return
        await socket.send_json({"t": "alive"})
        await asyncio.sleep(0.05)
    raise AssertionError(f"the board's last unit is not {wanted!r}: {web.sent()[-8:]}")


async def error(socket: aiohttp.ClientWebSocketResponse) -> str:
    while True:
        message = json.loads((await socket.receive(timeout=5)).data)
        if message["t"] == "error":
            return str(message["text"])


def test_every_route_needs_the_token_and_the_server_s_own_host(tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        for path in ("/", "/static/app.js", "/ws", "/nothing"):
            code, _, body = get(web.origin + path)
            assert code == 403 and "token" in body, (path, code, body)
        assert get(web.origin + "/?token=" + "x" * 32)[0] == 403
        code, headers, _ = get(web.address)
        assert code == 303 and headers["Location"] == "/"
        set_cookie = headers["Set-Cookie"]
        assert f"appmode_token={web.token}" in set_cookie
        assert "HttpOnly" in set_cookie and "SameSite=Strict" in set_cookie
        assert headers["Cache-Control"] == "no-store", "the token's answer is never kept"
        assert headers["Referrer-Policy"] == "no-referrer"
        code, headers, body = get(web.origin + "/", cookie(web))
        assert code == 200 and 'aria-label="forward"' in body
        assert "default-src 'self'" in headers["Content-Security-Policy"]
        port = web.origin.rsplit(":", 1)[1]
        rebound = {**cookie(web), "Host": f"attacker.example:{port}"}
        assert get(web.origin + "/", rebound)[0] == 403, "DNS rebinding: a foreign Host"
        assert get(web.origin + "/static/app.js", cookie(web))[0] == 200
        assert get(web.origin + "/static/../server.py", cookie(web))[0] in (403, 404)


def test_a_cross_site_page_cannot_open_the_websocket(tmp_path: Path) -> None:
    async def scenario(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            for origin in ("http://attacker.example", "null", web.origin.replace("http", "https")):
                try:
                    await page(session, web, origin)
                except aiohttp.WSServerHandshakeError as exc:
                    assert exc.status == 403
                else:
                    raise AssertionError(f"Origin {origin} was let in")
            socket = await page(session, web)
            assert (await status(socket))["role"] == "driver"
            await socket.close()

    with web_process(tmp_path) as web:
        asyncio.run(scenario(web))


def test_press_drives_heartbeats_keep_it_and_release_stops(tmp_path: Path) -> None:
    async def scenario(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            await socket.send_json({"t": "press", "key": "forward"})
            wait_sent(web, "A")
            for _ in range(10):  # 1 s of heartbeats: the car keeps going
                await asyncio.sleep(0.1)
                await socket.send_json({"t": "hold", "key": "forward"})
            assert web.sent()[-1] == "A"
            await socket.send_json({"t": "release"})
            wait_sent(web, "Z")
            await socket.send_json({"t": "press", "key": "front-right"})
            wait_sent(web, "B")
            await socket.send_json({"t": "press", "key": "stop"})
            wait_sent(web, "Z")
            await socket.close()

    with web_process(tmp_path) as web:
        asyncio.run(scenario(web))


def test_closing_the_page_stops_the_car(tmp_path: Path) -> None:
    async def scenario(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            await socket.send_json({"t": "press", "key": "left"})
            for _ in range(100):  # the page beats meanwhile, as it does: the lease holds
                if web.sent()[-1:] == ["G"]:
                    break
                await socket.send_json({"t": "alive"})
                await asyncio.sleep(0.05)
            assert web.sent()[-1:] == ["G"], web.sent()[-8:]
            await socket.close()
            wait_sent(web, "Z")

    with web_process(tmp_path) as web:
        asyncio.run(scenario(web))


def test_a_second_page_watches_until_it_takes_over_and_the_first_sees_it(
    tmp_path: Path,
) -> None:
    async def scenario(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            first = await page(session, web)
            assert (await ready(first))["role"] == "driver"
            second = await page(session, web)
            assert (await status(second))["role"] == "watcher"
            await second.send_json({"t": "press", "key": "forward"})
            assert "watches" in await error(second)
            await first.send_json({"t": "press", "key": "forward"})
            wait_sent(web, "A")
            for _ in range(3):
                await first.send_json({"t": "hold", "key": "forward"})
                await asyncio.sleep(0.05)
            await second.send_json({"t": "take"})
            wait_sent(web, "Z")  # a change of driver stops the car first
            while (await status(first))["role"] != "watcher":
                pass
            await second.send_json({"t": "press", "key": "right"})
            wait_sent(web, "C")
            await first.close()
            await second.close()
            wait_sent(web, "Z")

    with web_process(tmp_path) as web:
        asyncio.run(scenario(web))


def test_bad_messages_get_an_error_and_change_nothing(tmp_path: Path) -> None:
    async def scenario(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            before = web.sent()
            for bad in (
                "not json",
                "[]",
                '{"t": "press", "key": "up"}',
                '{"t": "press", "key": ["forward"]}',
                '{"t": "launch"}',
                '{"t": "command", "line": 5}',
                json.dumps({"t": "command", "line": "x" * 300}),
                '{"t": "command", "line": "quit"}',
            ):
                await socket.send_str(bad)
                assert await error(socket), bad
            await asyncio.sleep(0.3)
            assert web.sent() == before, "a bad message sent nothing to the board"
            await socket.send_str("x" * 5000)  # over the limit: the server closes it
            ends = (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED, aiohttp.WSMsgType.ERROR)
            for _ in range(50):  # statuses sent before it may come first
                if (await socket.receive(timeout=5)).type in ends:
                    break
            else:
                raise AssertionError("an over-long message did not close the websocket")
            await socket.close()
            flood = await page(session, web)  # the driver now
            await status(flood)
            await flood.send_json({"t": "press", "key": "forward"})
            wait_sent(web, "A")
            for _ in range(400):
                await flood.send_json({"t": "hold", "key": "forward"})
            assert "too many" in await error(flood)
            wait_sent(web, "Z")  # a page that floods loses the car
            await flood.close()
            assert (await status(await page(session, web)))["t"] == "status", "still serving"

    with web_process(tmp_path) as web:
        asyncio.run(scenario(web))


def test_a_command_line_sets_a_parameter_verified(tmp_path: Path) -> None:
    async def scenario(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            await socket.send_json({"t": "command", "line": "set max_speed 700"})
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline:
                shown = await status(socket)
                if any("max_speed = 700 (verified)" in m for m in shown["messages"]):
                    break
            else:
                raise AssertionError("the set was not verified")
            await socket.close()

    with web_process(tmp_path) as web:
        asyncio.run(scenario(web))
        assert "{0:700}" in web.sent()


def test_ending_the_server_while_driving_stops_the_car_last(tmp_path: Path) -> None:
    async def drive(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            await socket.send_json({"t": "press", "key": "forward"})
            wait_sent(web, "A")
            for sig in (signal.SIGTERM, signal.SIGHUP):  # two at once, as systemd sends
                web.proc.send_signal(sig)
            await asyncio.sleep(1.0)

    for trial in range(2):
        (tmp_path / str(trial)).mkdir()
        with web_process(tmp_path / str(trial)) as web:
            asyncio.run(drive(web))
            code, err = web.stop()
            assert code == 0 and "Traceback" not in err, err
            assert web.sent()[-1] == "Z", web.sent()[-5:]


def test_a_stick_that_goes_quiet_stops_the_car_and_the_app_port_takes_none(
    tmp_path: Path,
) -> None:
    async def quiet_stick(web: WebProcess) -> float:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket, "settings read")
            await socket.send_json({"t": "stick", "x": 0.5, "y": 1})
            push = "FF FE 01 00 96 01 2C"  # x 150, y 300; then the stop, its lease over: on
            # a busy machine both may be on the board before the test looks
            wait_frames(web, lambda frames: any(f.startswith(push) for f in frames), push)
            wait_frame(web, "FF FE 01 00 00 00 00 00 00 00", timeout=3)
            timed = web.timed_frames()  # on the board's clock: when each frame came
            pushed = max(t for t, frame in timed if frame.startswith(push))
            stopped = timed[-1][0] - pushed
            for bad in ({"x": 2, "y": 0}, {"x": True, "y": 0}, {"x": "1", "y": 0}, {}):
                await socket.send_json({"t": "stick", **bad})
                assert "−1…1" in await error(socket)
            await socket.close()
            return stopped

    with web_process(tmp_path, uart2=True) as web:
        assert 0.2 <= asyncio.run(quiet_stick(web)) < 1.5

    async def app_port(web: WebProcess) -> None:
        async with aiohttp.ClientSession() as session:
            socket = await page(session, web)
            await ready(socket)
            await socket.send_json({"t": "stick", "x": 0, "y": 1})
            assert "no analog steering" in await error(socket)
            await socket.close()

    (tmp_path / "app").mkdir()
    with web_process(tmp_path / "app") as web:
        asyncio.run(app_port(web))
