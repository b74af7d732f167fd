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


def module() -> str:
    """The vocabulary as an ES module: `SEND.press` is `"press"`, `RECEIVE.status`
    `"status"`; a kind a module of the page names and this does not is `undefined`."""
    send = json.dumps({kind: kind for kind in PAGE}, indent=1)
    receive = json.dumps({kind: kind for kind in SERVER}, indent=1)
    return (
        "// Made by appmode.web.messages: the kinds of message the page and the server\n"
        "// exchange, declared once in Python.\n"
        f"export const SEND = Object.freeze({send});\n"
        f"export const RECEIVE = Object.freeze({receive});\n"
    )
