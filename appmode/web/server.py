"""`appmode web`: the page a phone's (or any) browser opens to drive the car, served
with aiohttp on this machine.

Every request carries the owner's token (in the address printed once, then a cookie) and
a Host header naming this server; the websocket's Origin must be the page itself. The
session is ticked every REFRESH seconds; each page gets its status when it changes.
Whatever ends the server — Ctrl-C, SIGTERM, SIGHUP — the session closes, and its stop is
the last thing sent to the car.
"""

from __future__ import annotations

import asyncio
import json
import logging
import ssl
import sys
import time
from collections.abc import Awaitable, Callable
from contextlib import suppress
from importlib import resources
from typing import Any

from aiohttp import WSMsgType, web

from appmode.errors import AppmodeError
from appmode.host import signals
from appmode.session.base import BaseSession
from appmode.web import messages
from appmode.web.access import (
    COOKIE,
    host_allowed,
    is_loopback,
    new_token,
    origin_matches,
    token_matches,
)
from appmode.web.bridge import MAX_MESSAGE, Bridge
from appmode.web.certificate import grouped
from appmode.web.fleet import Fleet, FleetRoutes
from appmode.web.server_log import OneLine, one_line

HEADER_TIMEOUT = 10.0
"""Seconds a connection may take to send a whole request (aiohttp's keep-alive timeout
also closes a connection whose first request never completes)."""
MAX_CONNECTIONS = 64
GRACE = 2.0
"""Seconds without a token request after which a connection is a slow client's, at the cap."""
"""Connections served at once. Past them the oldest connection that has not yet made a
request with the token is closed (the newcomer, if every other one has): a flood of
half-sent requests churns, and can neither use up the server's open files nor lock its
owner out."""
REFRESH = 0.02
"""Seconds between reads of the link (and checks of the heartbeat)."""
SEND = 0.1
"""How often each page's status is checked, and sent if it changed."""
SCRIPTS = (
    "app.js",
    "link.js",
    "pad.js",
    "stick.js",
    "tilt.js",
    "instruments.js",
    "params.js",
    "waves.js",
)
"""The page's script: ES modules, `app.js` first (index.html preloads the rest)."""
ASSETS = (
    "index.html",
    "fleet.html",
    "fleet.js",
    *SCRIPTS,
    "app.css",
    "offline.html",
    "app.webmanifest",
    "icon.svg",
    "icon-192.png",
    "icon-512.png",
)
TYPES = {
    ".html": "text/html",
    ".js": "text/javascript",
    ".css": "text/css",
    ".webmanifest": "application/manifest+json",
    ".svg": "image/svg+xml",
    ".png": "image/png",
}
HEADERS = {
    "Cache-Control": "no-store",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Content-Security-Policy": "default-src 'self'; connect-src 'self'; frame-ancestors 'none'",
}


def _asset(name: str) -> bytes:
    return (resources.files("appmode.web") / "static" / name).read_bytes()


class WebServer:
    """The page and its websocket over one session (with `fleet`: over the session of
    the car chosen on the fleet page, if any)."""

    def __init__(
        self,
        session: BaseSession | None,
        host: str,
        port: int,
        tls: ssl.SSLContext | None = None,
        token: str | None = None,
        fleet: Fleet | None = None,
    ):
        self.session: BaseSession | None = None
        self.bridge: Bridge | None = None
        self.car: str | None = None
        """The fleet's car the session drives."""
        if session is not None:
            self.attach(session)
        self.tls = tls
        self.host = host
        self.port = port
        self.token = token or new_token()
        self._sockets: set[web.WebSocketResponse] = set()
        self._owners: set[object] = set()
        """The connections (aiohttp's handlers) that made a request with the token."""
        self._runner: web.AppRunner | None = None
        self.app = web.Application(middlewares=[self._guard], client_max_size=MAX_MESSAGE)
        self.fleet = None if fleet is None else FleetRoutes(self, fleet)
        self.app.router.add_get("/", self._index if self.fleet is None else self.fleet.index)
        if self.fleet is not None:
            self.fleet.add(self.app.router)
        self.app.router.add_get("/static/{name}", self._static)
        self.app.router.add_get("/sw.js", self._worker)
        self.app.router.add_get("/ws", self._websocket)

    def address(self, host: str | None = None) -> str:
        """What the owner opens: the page (at `host`, by default where it listens), with
        the token."""
        host = host or self.host
        shown = f"[{host}]" if ":" in host else host
        scheme = "https" if self.tls else "http"
        return f"{scheme}://{shown}:{self.port}/?token={self.token}"

    async def start(self) -> None:
        """Listen (port 0 picks a free one: `port` then says which)."""
        self._runner = _CappedRunner(
            self._owners,
            self.app,
            access_log=None,
            handle_signals=False,
            keepalive_timeout=HEADER_TIMEOUT,
        )
        await self._runner.setup()
        site = web.TCPSite(
            self._runner, self.host, self.port, shutdown_timeout=0.5, ssl_context=self.tls
        )
        try:
            await site.start()
        except OSError as exc:
            await self._runner.cleanup()
            where = f"{self.host}:{self.port}"
            raise AppmodeError(
                f"cannot serve the page on {where}: {exc.strerror or exc}; pick another "
                "address with --listen HOST:PORT (port 0 picks a free one)"
            ) from None
        self.port = self._runner.addresses[0][1]

    async def stop(self) -> None:
        for socket in list(self._sockets):
            await socket.close()
        if self._runner is not None:
            await self._runner.cleanup()

    def attach(self, session: BaseSession, fleet: str | None = None) -> None:
        """Drive `session` (the fleet's car `fleet`) from now on."""
        self.session, self.bridge, self.car = session, Bridge(session), fleet

    async def detach(self) -> BaseSession | None:
        """Stop serving the session (its pages' connections close): the session, for
        the caller to close."""
        session, self.session, self.bridge, self.car = self.session, None, None, None
        for socket in list(self._sockets):
            await socket.close()
        return session

    def page(self, name: str) -> web.Response:
        """One of the HTML pages."""
        return _compressed(web.Response(body=_asset(name), content_type="text/html"))

    def origin_refused(self, request: web.Request) -> web.Response | None:
        """A 403 for a websocket whose Origin is not this page, else None."""
        if origin_matches(request.headers.get("Origin"), request.host, request.scheme):
            return None
        return _refused("the websocket takes this page only (Origin)")

    # ------------------------------------------------------------ who may come in

    @web.middleware
    async def _guard(
        self, request: web.Request, handler: Callable[[web.Request], Awaitable[web.StreamResponse]]
    ) -> web.StreamResponse:
        if not host_allowed(request.headers.get("Host"), self.host, self.port):
            return _refused("this server answers only to its own address")
        if request.path == "/" and "token" in request.query:
            if not token_matches(self.token, request.query.get("token")):
                return _refused("wrong token: open the address appmode web printed")
            found = web.HTTPSeeOther("/", headers=HEADERS)  # the token leaves the address bar
            found.set_cookie(
                COOKIE,
                self.token,
                httponly=True,
                samesite="Strict",
                path="/",
                max_age=None,
                secure=self.tls is not None,  # never sent to a plain-HTTP server
            )
            return found
        if not token_matches(self.token, request.cookies.get(COOKIE)):
            return _refused("no token: open the address appmode web printed, with its token")
        self._owners.add(request.protocol)
        response = await handler(request)
        response.headers.update(HEADERS)
        return response

    # ------------------------------------------------------------ routes

    async def _index(self, request: web.Request) -> web.StreamResponse:
        return self.page("index.html")

    async def _static(self, request: web.Request) -> web.StreamResponse:
        name = request.match_info["name"]
        if name == "messages.js":  # the vocabulary, made from Python
            body = messages.module().encode()
            return _compressed(web.Response(body=body, content_type="text/javascript"))
        if name not in ASSETS:
            raise web.HTTPNotFound()
        kind = TYPES[name[name.rindex(".") :]]
        return _compressed(web.Response(body=_asset(name), content_type=kind))

    async def _worker(self, request: web.Request) -> web.StreamResponse:
        """The service worker, from the root: its scope is the whole page."""
        return _compressed(web.Response(body=_asset("sw.js"), content_type="text/javascript"))

    async def _websocket(self, request: web.Request) -> web.StreamResponse:
        refused = self.origin_refused(request)
        if refused is not None:
            return refused
        bridge = self.bridge
        if bridge is None:
            return web.Response(
                status=409, text="409: no car is chosen: pick one on the fleet page\n"
            )
        socket = web.WebSocketResponse(max_msg_size=MAX_MESSAGE, heartbeat=5.0)
        await socket.prepare(request)
        self._sockets.add(socket)
        bridge.join(socket)
        sender = asyncio.ensure_future(self._send_status(socket, bridge))
        try:
            async for message in socket:
                if message.type in (WSMsgType.TEXT, WSMsgType.BINARY):
                    reply = bridge.handle(socket, message.data)
                    if reply is not None:
                        await socket.send_str(json.dumps(reply))
        finally:
            sender.cancel()
            self._sockets.discard(socket)
            bridge.leave(socket)
        return socket

    async def _send_status(self, socket: web.WebSocketResponse, bridge: Bridge) -> None:
        """The page's status whenever it changed, until its connection ends (a send to a
        connection that broke ends it too: the receiving side then sees it close)."""
        shown = ""
        with suppress(ConnectionError, RuntimeError):
            while not socket.closed:
                text = json.dumps({**bridge.status(socket), "fleet": self.car})
                if text != shown:
                    shown = text
                    await socket.send_str(text)
                await asyncio.sleep(SEND)

    # ------------------------------------------------------------ running

    async def run(self, announce: Callable[[WebServer], None]) -> None:
        """Serve until an ending signal (or Ctrl-C); the session ticks meanwhile."""
        loop = asyncio.get_running_loop()
        loop.set_exception_handler(one_line)
        ended = asyncio.Event()

        def on_signal() -> None:
            loop.call_soon_threadsafe(ended.set)

        with signals.diverted(on_signal):
            await self.start()
            announce(self)
            try:
                while not ended.is_set():
                    if self.session is not None:
                        self.session.tick()
                    await asyncio.sleep(REFRESH)  # a signal is acted on within it
            finally:
                await self.stop()


class _CappedRunner(web.AppRunner):
    """An AppRunner whose server, past MAX_CONNECTIONS, closes the oldest connection that
    has made no request with the token (`owners` have) for GRACE seconds: a slow client's;
    failing one, the oldest of the owners' that waits idle for a next request (a browser
    keeps several open a page: ten pages of the owner's filled the cap); failing that, the
    oldest without the token, at worst the newcomer. A browser opens a page's connections
    at once and asks at once: the young ones are the owner's next page's, not taken first."""

    def __init__(self, owners: set[object], *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._owners = owners

    async def _make_server(self) -> web.Server:
        server = await super()._make_server()
        made, lost, owners = server.connection_made, server.connection_lost, self._owners
        since: dict[object, float] = {}  # when each live connection was made

        def connection_made(handler: Any, transport: asyncio.Transport) -> None:
            made(handler, transport)
            now = since[handler] = time.monotonic()
            connections = server.connections  # oldest first
            if len(connections) <= MAX_CONNECTIONS:
                return
            open_ = [c for c in connections if c.transport and not c.transport.is_closing()]
            strangers = [c for c in open_ if c not in owners]
            slow = (c for c in strangers if now - since.get(c, now) >= GRACE)
            idle = (c for c in open_ if c in owners and not _busy(c))
            victim = next(slow, None) or next(idle, None) or next(iter(strangers), None)
            if victim is not None and victim.transport is not None:
                victim.transport.close()

        def connection_lost(handler: Any, exc: BaseException | None = None) -> None:
            owners.discard(handler)  # the sets hold live connections only
            since.pop(handler, None)
            lost(handler, exc)

        server.connection_made = connection_made  # type: ignore[method-assign]
        server.connection_lost = connection_lost  # type: ignore[method-assign]
        return server


def _busy(handler: Any) -> bool:
    """Whether a connection is serving a request (a page's WebSocket), not idle."""
    return bool(getattr(handler, "_request_in_progress", True))


def _compressed(response: web.Response) -> web.Response:
    """The page's own files, compressed for a browser that takes it (a third of the
    bytes over a phone's Wi-Fi); none holds a secret (the token is in a cookie)."""
    if not response.content_type.startswith("image/png"):
        response.enable_compression()
    return response


def _refused(text: str) -> web.Response:
    return web.Response(status=403, text=f"403: {text}\n", headers=HEADERS)


def qr_code(address: str) -> str:
    """`address` as a QR code of text blocks (two rows a line), for a phone's camera."""
    import io

    import segno  # QR codes in pure Python: no image library, no terminal of ours

    out = io.StringIO()
    segno.make(address, error="l").terminal(out=out, compact=True, border=2)
    return out.getvalue().rstrip("\n")


def serve_web(
    session: BaseSession | None,
    host: str,
    port: int,
    tls: ssl.SSLContext | None = None,
    names: tuple[str, ...] = (),
    fingerprint: str | None = None,
    fleet: Fleet | None = None,
) -> int:
    """Start the session, serve the page until ended, and always close the session: its
    stop is the last thing sent (exit status 1 if the recording stopped on its own, or
    the stop could not be sent to a car last told to move). With `fleet` (and no
    session) the page shows the fleet, and drives the car chosen there.
    `names` are other addresses the page is reached at; a self-signed certificate's
    `fingerprint` is printed for the owner to check."""
    for name in ("aiohttp", "asyncio"):
        server_log = logging.getLogger(name)
        server_log.addHandler(OneLine())
        server_log.propagate = False

    def announce(server: WebServer) -> None:
        first = names[0] if names else None
        print(f"web: {server.address(first)}", flush=True)
        for other in names[1:]:
            print(f"appmode: also at {server.address(other)}", file=sys.stderr)
        if first is not None:
            print(
                f"appmode: to open it on a phone, scan:\n{qr_code(server.address(first))}",
                file=sys.stderr,
            )
        if fingerprint is not None:
            lines = "".join(f"\nappmode:   {line}" for line in grouped(fingerprint))
            print(
                "appmode: the page's certificate is appmode's own (self-signed); the "
                f"browser asks once: accept it if its SHA-256 fingerprint is{lines}",
                file=sys.stderr,
            )
        if not is_loopback(host):
            print(
                f"appmode: WARNING: the page is served on {host}:{server.port}: every device "
                "that reaches this machine there can open it; only the token keeps it from "
                "driving the car",
                file=sys.stderr,
            )
        print(
            "appmode: open that address in a browser; Ctrl-C stops the car and the server",
            file=sys.stderr,
            flush=True,
        )

    server: WebServer | None = None
    try:
        if session is not None:
            session.start()
        if fleet is not None:
            fleet.start()
        server = WebServer(session, host, port, tls, fleet=fleet)
        asyncio.run(server.run(announce))
    finally:
        if fleet is not None:
            fleet.close()
        last = session if server is None else server.session
        failed = last is not None and _close(last)
    return 1 if failed else 0


def _close(session: BaseSession) -> bool:
    """Close the session (its stop last), saying what went wrong: whether it failed (the
    recording stopped on its own, or the car last told to move did not get the stop)."""
    session.close()
    for note in session.closing_notes:
        print(f"appmode: WARNING: {note}", file=sys.stderr)
    if session.recording_failure is not None:
        print(f"appmode: error: {session.recording_failure}", file=sys.stderr)
    if session.undelivered is not None:
        print(f"appmode: {session.undelivered}", file=sys.stderr)
    return session.recording_failure is not None or session.left_moving
