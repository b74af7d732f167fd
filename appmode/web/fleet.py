"""`appmode web --fleet`: every car a key opens (shares on Zenoh) as a card on a page —
battery, what is in force, its links, who drives — with a button that stops them all;
tapping a card drives that car on the usual page, through a session this server opens
on it (one car at a time: choosing another stops and closes the first).

The cars are looked at every LOOK seconds in a thread of their own (a look waits for the
cars' answers); the page gets them over a websocket of its own (`/fleet/ws`), as it gets
the car's status. A car is named by the page, checked against the cars that answered:
the key never reaches the page."""

from __future__ import annotations

import asyncio
import json
import threading
from collections.abc import Callable
from contextlib import suppress
from typing import TYPE_CHECKING, Any

from aiohttp import WSMsgType, web

from appmode.errors import AppmodeError
from appmode.net.fleet import cars, stop_all
from appmode.ports.remote import NAME
from appmode.web.messages import FLEET_PAGE

if TYPE_CHECKING:
    import zenoh

    from appmode.net.signature import Trust
    from appmode.session.base import BaseSession
    from appmode.web.server import WebServer

LOOK = 1.0
"""Seconds between two looks at the fleet."""
SEND = 0.25
"""How often each fleet page's cards are checked, and sent if they changed."""
CARD_FIELDS = (
    "name", "profile", "simulated", "links", "driver", "battery", "in_force", "moving",
)  # fmt: skip
VANISHED = "its host stopped answering: it may still be moving"
"""What the card of a car that was moving says once its host no longer answers."""


class Fleet:
    """The cars `session` reaches (what their hosts signed: `trust`), looked at until
    `close`; `open_car(name)` opens a driving session on one of them."""

    def __init__(
        self, session: zenoh.Session, trust: Trust, open_car: Callable[[str], BaseSession]
    ) -> None:
        self.session = session
        self.trust = trust
        self.open_car = open_car
        self.cars: list[dict[str, Any]] = []
        self._ended = threading.Event()
        self._looking = threading.Thread(target=self._look, name="fleet look", daemon=True)

    def start(self) -> None:
        self._looking.start()

    def _look(self) -> None:
        while not self._ended.is_set():
            found = cars(self.session, self.trust, wait=LOOK)
            answered = [
                {
                    **{k: car.info.get(k) for k in CARD_FIELDS[1:]},
                    "name": car.name,
                    "latency_ms": round(car.latency_ms, 1),
                }
                for car in found
            ]
            names = {card["name"] for card in answered}
            kept = [  # a car last seen moving whose host is gone is no stopped car
                {**card, "in_force": VANISHED, "vanished": True}
                for card in self.cars
                if card["name"] not in names and (card.get("moving") or card.get("vanished"))
            ]
            self.cars = sorted([*answered, *kept], key=lambda card: str(card["name"]))
            self._ended.wait(LOOK / 2)

    def known(self, name: str) -> bool:
        """Whether `name` is a car that answered (a page names nothing else)."""
        return NAME.fullmatch(name) is not None and any(
            c["name"] == name and not c.get("vanished") for c in self.cars
        )

    def stop_all(self) -> list[dict[str, Any]]:
        """Stop every car; each one's answer (blocks up to a few seconds)."""
        return stop_all(self.session, self.trust)

    def close(self) -> None:
        self._ended.set()


class FleetRoutes:
    """The fleet page's routes on a `WebServer` (`server`): `/` the cards, `/car/NAME`
    the drive page of that car, `/fleet/ws` the cards live and the stop-all."""

    def __init__(self, server: WebServer, fleet: Fleet) -> None:
        self.server = server
        self.fleet = fleet
        self.driving: str | None = None
        self._switching = asyncio.Lock()

    def add(self, router: web.UrlDispatcher) -> None:
        router.add_get("/car/{name}", self._car)
        router.add_get("/fleet/ws", self._websocket)

    async def index(self, request: web.Request) -> web.StreamResponse:
        return self.server.page("fleet.html")

    async def _car(self, request: web.Request) -> web.StreamResponse:
        name = request.match_info["name"]
        if not self.fleet.known(name):
            raise web.HTTPNotFound(text=f"404: no car {name[:64]!r} answers now\n")
        async with self._switching:
            if name != self.driving:
                await self._switch(name)
        return self.server.page("index.html")

    async def _switch(self, name: str) -> None:
        """Close the car driven now (its stop is sent) and open `name`'s session."""
        loop = asyncio.get_running_loop()
        old = await self.server.detach()
        self.driving = None
        if old is not None:
            await loop.run_in_executor(None, old.close)
        try:
            session = await loop.run_in_executor(None, self.fleet.open_car, name)
        except AppmodeError as exc:
            raise web.HTTPBadGateway(text=f"502: cannot open {name}: {exc}\n") from None
        self.driving = name
        self.server.attach(session, fleet=name)

    async def _websocket(self, request: web.Request) -> web.StreamResponse:
        refused = self.server.origin_refused(request)
        if refused is not None:
            return refused
        socket = web.WebSocketResponse(max_msg_size=256, heartbeat=5.0)
        await socket.prepare(request)
        sender = asyncio.ensure_future(self._send_cards(socket))
        try:
            async for message in socket:
                if message.type is not WSMsgType.TEXT:
                    continue
                if _kind(message.data) not in FLEET_PAGE:  # stop_all
                    await socket.send_str(json.dumps({"t": "error", "text": "unknown message"}))
                    continue
                answers = await self._stop_all()
                await socket.send_str(json.dumps({"t": "stopped", "answers": answers}))
        finally:
            sender.cancel()
        return socket

    async def _stop_all(self) -> list[dict[str, Any]]:
        """The car driven here stops as its page's stop would; then every car's host
        stops its car and says whether it took."""
        session = self.server.session
        if session is not None:
            session.stop()
        return await asyncio.get_running_loop().run_in_executor(None, self.fleet.stop_all)

    async def _send_cards(self, socket: web.WebSocketResponse) -> None:
        shown = ""
        with suppress(ConnectionError, RuntimeError):
            while not socket.closed:
                text = json.dumps({"t": "fleet", "cars": self.fleet.cars, "driving": self.driving})
                if text != shown:
                    shown = text
                    await socket.send_str(text)
                await asyncio.sleep(SEND)


def _kind(text: str) -> str | None:
    try:
        message = json.loads(text)
    except ValueError:
        return None
    kind = message.get("t") if isinstance(message, dict) else None
    return kind if isinstance(kind, str) else None
