"""`appmode drive`: the full-screen console, and its script mode for stdin that is no TTY.

A prompt_toolkit Application (not a PromptSession, which would take the arrow keys for
history): the status panel, the 3×3 key grid and arrows to drive, and a command line
(`:`) with completion and history. Whatever ends it, the session's close sends `Z` last.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Iterable
from typing import TextIO

from prompt_toolkit.application import Application
from prompt_toolkit.buffer import Buffer
from prompt_toolkit.completion import NestedCompleter
from prompt_toolkit.filters import Condition
from prompt_toolkit.history import InMemoryHistory
from prompt_toolkit.input import Input
from prompt_toolkit.key_binding import KeyBindings, KeyPressEvent
from prompt_toolkit.layout import ConditionalContainer, HSplit, Layout, VSplit, Window
from prompt_toolkit.layout.controls import BufferControl, FormattedTextControl
from prompt_toolkit.output import Output

from appmode.console.panel import ARROWS, KEY_GRID, status_fragments, status_text
from appmode.console.session import (
    COMMAND_NAMES,
    MESSAGES,
    PAGE_WORDS,
    Quit,
    Session,
    ShowStatus,
)
from appmode.host.signals import ENDING_SIGNALS
from appmode.host.tokens import Wait
from appmode.protocol import params
from appmode.protocol.directions import grid_for

REFRESH = 0.02
"""Seconds between reads of the link (and checks of the hold-to-drive timers)."""
REDRAW = 0.1
"""How often the panel is checked, and redrawn if what it shows changed (a key redraws at
once)."""


def _completer() -> NestedCompleter:
    names = {p.name: None for p in params.PARAMS}
    table: dict[str, object] = {name: None for name in COMMAND_NAMES}
    table.update(
        set=names,
        page={word: None for word in PAGE_WORDS},
        latch={"on": None, "off": None},
        record={"stop": None},
        speed={"+100": None, "-100": None},
    )
    return NestedCompleter.from_nested_dict(table)


def build_app(
    session: Session, input: Input | None = None, output: Output | None = None
) -> Application[None]:
    """The console's Application over a started session."""
    history = InMemoryHistory()
    command = Buffer(
        multiline=False, completer=_completer(), history=history, complete_while_typing=True
    )
    status = Window(
        FormattedTextControl(lambda: status_fragments(session), focusable=True),
        wrap_lines=False,
        dont_extend_height=True,
    )
    messages = Window(
        FormattedTextControl(lambda: "\n".join(session.messages)), height=MESSAGES, wrap_lines=True
    )
    command_line = VSplit(
        [Window(FormattedTextControl(":"), width=1), Window(BufferControl(command), height=1)]
    )
    typing = Condition(lambda: app.layout.has_focus(command))
    driving = ~typing
    keys = KeyBindings()

    def drive_key(row: int, col: int) -> None:
        session.press(grid_for(session.page)[row][col])

    for r, row in enumerate(KEY_GRID):
        for c, key in enumerate(row):
            keys.add(key, filter=driving)(lambda e, r=r, c=c: drive_key(r, c))
            keys.add(key.upper(), filter=driving)(lambda e, r=r, c=c: drive_key(r, c))
    for arrow, (r, c) in ARROWS.items():
        keys.add(arrow, filter=driving)(lambda e, r=r, c=c: drive_key(r, c))
    keys.add(" ", filter=driving)(lambda e: session.stop())
    for letter in "IJK":
        keys.add(letter.lower(), filter=driving)(lambda e, x=letter: session.switch_page(x))
    keys.add("l", filter=driving)(
        lambda e: session.run("latch off" if session.driving.latched else "latch on")
    )
    keys.add("+", filter=driving)(lambda e: session.run("speed +100"))
    keys.add("=", filter=driving)(lambda e: session.run("speed +100"))
    keys.add("-", filter=driving)(lambda e: session.run("speed -100"))
    keys.add("p", filter=driving)(lambda e: session.run("params"))
    keys.add("?", filter=driving)(lambda e: session.run("help"))

    @keys.add(":", filter=driving)
    def _command(event: KeyPressEvent) -> None:
        session.stop()  # the keys stop driving while typing: never leave the car moving
        event.app.layout.focus(command)

    @keys.add("escape", filter=typing, eager=True)
    def _leave(event: KeyPressEvent) -> None:
        command.reset()
        event.app.layout.focus(status)

    @keys.add("enter", filter=typing)
    def _run(event: KeyPressEvent) -> None:
        text = command.text
        command.append_to_history()
        command.reset()
        event.app.layout.focus(status)
        try:
            step = session.run(text)
        except Quit:
            event.app.exit()
            return
        if isinstance(step, Wait):
            session.say("wait is for script mode")
        _show(session, step)

    @keys.add("c-c")
    @keys.add("c-q")
    @keys.add("Q", filter=driving)
    def _quit(event: KeyPressEvent) -> None:
        event.app.exit()

    layout = Layout(
        HSplit(
            [
                status,
                Window(height=1, char="─"),
                messages,
                ConditionalContainer(command_line, filter=typing),
            ]
        ),
        focused_element=status,
    )
    app: Application[None] = Application(
        layout=layout, key_bindings=keys, full_screen=True, input=input, output=output
    )
    return app


async def run_app(app: Application[None], session: Session) -> None:
    """Run the console until quit; the link is read every REFRESH seconds."""

    async def ticker() -> None:
        # A failure here must end the console (and so stop the car), not leave it
        # running without release emulation behind prompt_toolkit's "Press ENTER".
        checked = 0.0
        shown = ""
        try:
            while True:
                session.tick()
                now = time.monotonic()
                if now - checked >= REDRAW:  # redraw only when what is shown changed
                    checked = now
                    text = status_text(session) + "\n".join(session.messages)
                    if text != shown:
                        shown = text
                        app.invalidate()
                await asyncio.sleep(REFRESH)
        except Exception as exc:
            app.exit(exception=exc)

    def start_ticker() -> None:
        app.create_background_task(ticker())

    loop = asyncio.get_running_loop()
    for signum in ENDING_SIGNALS:
        loop.add_signal_handler(signum, app.exit)
    try:
        await app.run_async(pre_run=start_ticker)
    finally:
        for signum in ENDING_SIGNALS:
            loop.remove_signal_handler(signum)


def run_drive(
    session: Session,
    interactive: bool,
    script: Iterable[str],
    out: TextIO,
    input: Input | None = None,
    output: Output | None = None,
) -> int:
    """Start the session, run the console (or script mode), and always close it: `Z` last."""
    try:
        session.start()
        if interactive:
            asyncio.run(run_app(build_app(session, input, output), session))
        else:
            run_script(session, script, out)
    finally:
        session.close()
    return 0


def run_script(session: Session, lines: Iterable[str], out: TextIO) -> int:
    """Script mode: run commands line by line; `wait S` lets S seconds pass.

    A parameter read or set finishes before the next line runs.
    """
    _settle(session, 0.0)
    for raw in lines:
        try:
            step = session.run(raw)
        except Quit:
            break
        _show(session, step)
        _settle(session, step.seconds if isinstance(step, Wait) else 0.0)
    out.flush()
    return 0


def _show(session: Session, step: Wait | ShowStatus | None) -> None:
    """What a command returned for the view: the panel for `status`."""
    if isinstance(step, ShowStatus):
        session.say(status_text(session))


def _settle(session: Session, seconds: float) -> None:
    """Let `seconds` pass, and any parameter query end, reading the link meanwhile."""
    end = time.monotonic() + seconds
    session.tick()
    while time.monotonic() < end or session.host.state.query is not None:
        time.sleep(min(REFRESH, max(0.0, end - time.monotonic())) or REFRESH)
        session.tick()
