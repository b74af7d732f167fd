"""The page↔server vocabulary, declared once: what a page may send (`PAGE`) and what the
server sends it (`SERVER`), each kind with what it means. The bridge handles exactly
`PAGE`; the page's script imports both as the module `messages.js` (`module()`), so a
kind neither side knows cannot be written by one side only."""

from __future__ import annotations

import json

PAGE = {
    "alive": "the page's heartbeat: any motion lasts only while it comes",
    "take": "a watching page takes the driving over (the car stops first)",
    "waves": "`on`: whether this page draws waveforms (its status then carries the traces)",
    "press": "a key or cell pressed: `key`, what it drives (`forward`, `rotate-cw`, `stop`)",
    "hold": "the same key still held: its repeat",
    "stick": "an analog stick's position, `x` and `y` in −1…1, repeated while held",
    "release": "the key or stick let go: the car stops",
    "stop": "stop now",
    "command": "a command line, `line` (`set max_speed 800`, `save`, `help`)",
}
"""What a page sends: `{"t": KIND, …}`."""
SERVER = {
    "status": "what the page shows now, sent whenever it changed",
    "error": "`text`: what a message of the page could not do",
}
"""What the server sends a page: `{"t": KIND, …}`."""
FLEET_PAGE = {
    "stop_all": "stop every car the key opens (each car's host confirms its stop)",
}
"""What the fleet page (`web --fleet`) sends."""
FLEET_SERVER = {
    "fleet": "`cars`: each car as its host describes it; `driving`: the car driven here",
    "stopped": "`answers`: each car's answer to a stop-all (`name`, `sent`, `confirmed`)",
    "error": "`text`: what a message of the page could not do",
}
"""What the server sends the fleet page."""


def module() -> str:
    """The vocabulary as an ES module: `SEND.press` is `"press"`, `RECEIVE.status`
    `"status"`; a kind a module of the page names and this does not is `undefined`."""
    tables = {
        "SEND": PAGE,
        "RECEIVE": SERVER,
        "FLEET_SEND": FLEET_PAGE,
        "FLEET_RECEIVE": FLEET_SERVER,
    }
    lines = [
        "// Made by appmode.web.messages: the kinds of message the pages and the server",
        "// exchange, declared once in Python.",
    ]
    for name, table in tables.items():
        kinds = json.dumps({kind: kind for kind in table}, indent=1)
        lines.append(f"export const {name} = Object.freeze({kinds});")
    return "\n".join(lines) + "\n"
