"""The page↔server vocabulary, declared once in Python (issue 65.4): every kind the
page's script sends is one the bridge handles and the other way round; the page's
script is modules, each small; the vocabulary the page loads is made from Python."""

from __future__ import annotations

import re
from pathlib import Path

from appmode.web import messages
from appmode.web.bridge import Bridge
from appmode.web.server import SCRIPTS
from tests.support.sessions import session

STATIC = Path(messages.__file__).parent / "static"


def script() -> str:
    return "\n".join((STATIC / name).read_text(encoding="utf-8") for name in SCRIPTS)


def test_what_the_page_sends_is_what_the_bridge_handles_and_the_other_way_round() -> None:
    sent = set(re.findall(r"\bSEND\.(\w+)", script()))
    board = session("sim://")
    try:
        handled = set(Bridge(board)._handlers)
    finally:
        board.close()
    assert sent == set(messages.PAGE), sent ^ set(messages.PAGE)
    assert handled == set(messages.PAGE), handled ^ set(messages.PAGE)
    received = set(re.findall(r"\bRECEIVE\.(\w+)", script()))
    assert received == set(messages.SERVER)
    assert not re.search(r"""\bt:\s*["']""", script()), "a kind written as a string"


def test_the_page_loads_the_vocabulary_python_declares() -> None:
    module = messages.module()
    for kind in (*messages.PAGE, *messages.SERVER):
        assert f'"{kind}": "{kind}"' in module
    assert "export const SEND = Object.freeze(" in module


def test_the_script_is_small_modules_and_the_safety_core_stands_apart() -> None:
    sizes = {name: len((STATIC / name).read_text().splitlines()) for name in SCRIPTS}
    assert len(sizes) >= 4 and max(sizes.values()) < 300, sizes
    core = (STATIC / "link.js").read_text()
    for part in ("new WebSocket", "HEARTBEAT_MS", "releaseAll", "lostConnection"):
        assert part in core
    others = "\n".join((STATIC / n).read_text() for n in SCRIPTS if n != "link.js")
    assert "new WebSocket" not in others and "setInterval(() => send({ t: SEND.alive" not in others
