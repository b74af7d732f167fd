"""The full-screen console: a prompt_toolkit Application over a driving session.

Not a PromptSession, which would take the arrow keys for history: the status panel, the
3×3 key grid and arrows to drive, a message log, and a command line (`:`) with
completion and history. Its key bindings come in three sets — driving, the view, the
command line — merged as prompt_toolkit's own full-screen examples do.
"""

from __future__ import annotations

import asyncio
import os
import time
from contextlib import suppress

from prompt_toolkit.application import Application
from prompt_toolkit.buffer import Buffer
from prompt_toolkit.completion import NestedCompleter
from prompt_toolkit.filters import Condition, has_focus
from prompt_toolkit.history import FileHistory, History, InMemoryHistory
from prompt_toolkit.input import Input
from prompt_toolkit.key_binding import KeyBindings, KeyPressEvent, merge_key_bindings
from prompt_toolkit.layout import (
    ConditionalContainer,
    Float,
    FloatContainer,
    HSplit,
    Layout,
    VSplit,
    Window,
)
from prompt_toolkit.layout.controls import BufferControl, FormattedTextControl
from prompt_toolkit.layout.menus import CompletionsMenu
from prompt_toolkit.output import Output

from appmode.console.log import MESSAGES, MessageLog
from appmode.console.panel import status_fragments
from appmode.console.panel_parts import ARROWS, KEY_GRID, Fragments
from appmode.console.script import show
from appmode.files import data_folder
from appmode.host import signals
from appmode.host.waits import Wait
from appmode.session.base import BaseSession
from appmode.session.command_line import QUIT_WORDS, Quit, ShowHelp
from appmode.session.rows import WIDTH

REFRESH = 0.02
"""Seconds between reads of the link (and checks of the hold-to-drive timers)."""
REDRAW = 0.1
"""How often the panel is checked, and redrawn if what it shows changed (a key redraws at
once)."""

HELP_TITLE = "help · ? or Esc close · PgUp/PgDn scroll"
NO_WAVES = (
    "no waveforms on the control port's console: they plot the APP port's A and B "
    "records (appmode drive APP_URL)"
)


class Console:
    """The console over a started session; `run()` until it is quit."""

    def __init__(
        self,
        session: BaseSession,
        input: Input | None = None,
        output: Output | None = None,
        history: History | None = None,
    ) -> None:
        self.session = session
        self.top = "panel"
        """What is shown above the messages: "panel", "waves" (the panel with waveforms)
        or "help"."""
        self.help_first = 0
        """The first line of the help shown (PageUp / PageDown while it is shown)."""
        self._warned = False
        # Completions show on Tab only, not while typing.
        self.command = Buffer(
            multiline=False,
            completer=_completer(session),
            history=history or InMemoryHistory(),
            complete_while_typing=False,
        )
        self.typing = has_focus(self.command)
        self.log = MessageLog(session.messages)
        self.status = Window(
            FormattedTextControl(self._top, focusable=True),
            wrap_lines=False,
            dont_extend_height=True,
        )
        rule = Window(FormattedTextControl(self._rule), height=1, style="fg:ansibrightblack")
        prompt = VSplit(
            [
                Window(FormattedTextControl(":"), width=1),
                Window(BufferControl(self.command), height=1),
            ]
        )
        body = HSplit(
            [self.status, rule, self.log.window, ConditionalContainer(prompt, filter=self.typing)]
        )
        menu = Float(xcursor=True, ycursor=True, content=CompletionsMenu(max_height=8))
        self.app: Application[None] = Application(
            layout=Layout(FloatContainer(body, floats=[menu]), focused_element=self.status),
            key_bindings=merge_key_bindings(
                [self._drive_keys(), self._view_keys(), self._command_keys()]
            ),
            full_screen=True,
            input=input,
            output=output,
            before_render=self.log.sync,
        )

    # ------------------------------------------------------------ key bindings

    def _drive_keys(self) -> KeyBindings:
        """The grid, the arrows, the session's own keys; only while not typing."""
        session, keys = self.session, KeyBindings()
        driving = ~self.typing

        def press(what: str) -> object:
            # a held key repeats some 30 times a second: a repeat that changes nothing
            # shown is not drawn again (NotImplemented tells prompt_toolkit so), which
            # keeps the console's CPU, and so its wait for one on a busy machine, low
            shown = _shown(session)
            session.press(what)
            return NotImplemented if _shown(session) == shown else None

        for r, row in enumerate(KEY_GRID):
            for c, key in enumerate(row):
                for name in (key, key.upper()):
                    keys.add(name, filter=driving)(
                        lambda e, r=r, c=c: press(session.grid_key(r, c))
                    )
        for arrow, (r, c) in ARROWS.items():
            keys.add(arrow, filter=driving)(lambda e, r=r, c=c: press(session.grid_key(r, c)))
        for key, what in session.hold_keys.items():
            keys.add(key, filter=driving)(lambda e, what=what: press(what))
        keys.add(" ", filter=driving)(lambda e: session.stop())
        for key, line in session.keys.items():
            keys.add(key, filter=driving)(lambda e, line=line: self._key_command(line))
        keys.add("l", filter=driving)(
            lambda e: self._key_command("latch off" if session.driving.latched else "latch on")
        )
        keys.add("c-c")(lambda e: e.app.exit())  # at once: the session's close says what
        keys.add("c-q")(lambda e: self.leave())
        return keys

    def _view_keys(self) -> KeyBindings:
        """Help, waveforms, scrolling."""
        keys = KeyBindings()
        driving = ~self.typing
        keys.add("?", filter=driving)(lambda e: self.toggle("help"))
        if self.session.waveforms:
            keys.add("v", filter=driving)(lambda e: self.toggle("waves"))
        else:
            keys.add("v", filter=driving)(lambda e: self.session.say(NO_WAVES))
        keys.add("escape", filter=driving & Condition(lambda: self.top != "panel"))(
            lambda e: self.toggle(self.top)
        )
        keys.add("pageup")(lambda e: self.scroll(1))
        keys.add("pagedown")(lambda e: self.scroll(-1))
        keys.add("end", filter=driving)(lambda e: self.log.newest())
        return keys

    def _command_keys(self) -> KeyBindings:
        """`:` opens the command line; Enter runs it, Esc leaves it; ↑ ↓ its history."""
        keys, command, typing = KeyBindings(), self.command, self.typing

        @keys.add(":", filter=~typing)
        def _open(event: KeyPressEvent) -> None:
            self.session.stop()  # the keys stop driving while typing: never leave it moving
            event.app.layout.focus(command)

        @keys.add("escape", filter=typing, eager=True)
        def _close(event: KeyPressEvent) -> None:
            command.reset()
            event.app.layout.focus(self.status)

        # While typing, ↑ and ↓ walk the history, never a completion menu (Tab and
        # Shift-Tab do): `:`, Tab, ↑ used to pick the menu's last entry, `quit`.
        @keys.add("up", filter=typing)
        def _older(event: KeyPressEvent) -> None:
            command.cancel_completion()
            command.history_backward()

        @keys.add("down", filter=typing)
        def _newer(event: KeyPressEvent) -> None:
            command.cancel_completion()
            command.history_forward()

        @keys.add("enter", filter=typing)
        def _run(event: KeyPressEvent) -> None:
            text = command.text
            command.reset()
            event.app.layout.focus(self.status)
            failures = self.session.failures
            self.run_line(text)
            # kept if the session took it: never a refused line (a paste of 100 kB), never
            # quit (one ↑ and Enter away)
            if self.session.failures == failures and text.strip() and not is_quit(text):
                command.history.append_string(text)

        return keys

    # ------------------------------------------------------------ what keys do

    def run_line(self, text: str) -> None:
        """A command line typed after `:`."""
        try:
            step = self.session.run(text)
        except Quit:
            self.leave()
            return
        if isinstance(step, Wait):
            self.session.say("wait is for script mode")
        elif isinstance(step, ShowHelp):
            self.top = "help"  # the whole of it, in place of the panel
        else:
            show(self.session, step)

    def _key_command(self, line: str) -> None:
        """A key that runs a command line; a quit from it would be a surprise: none do."""
        with suppress(Quit):
            self.session.run(line)

    def leave(self) -> None:
        """Quit; the first time, if values were set and not saved, only say so."""
        warning = self.session.unsaved_warning()
        if warning is not None and not self._warned:
            self._warned = True
            self.session.say(f"{warning} — :save keeps it; quit again to leave")
            return
        self.app.exit()

    def toggle(self, name: str) -> None:
        self.top = "panel" if self.top == name else name
        self.help_first = 0

    def scroll(self, pages: int) -> None:
        """PgUp/PgDn: the help while it is shown, else the messages."""
        if self.top != "help":
            self.log.scroll(pages)
            return
        info = self.status.render_info
        shown = info.window_height if info else MESSAGES
        last = max(0, len(self.session.help_lines) + 1 - shown)
        self.help_first = min(last, max(0, self.help_first - max(1, shown - 1) * pages))

    # ------------------------------------------------------------ what it shows

    def _top(self) -> Fragments:
        if self.top == "help":
            lines = [HELP_TITLE, *self.session.help_lines][self.help_first :]
            return [("", "\n".join(lines))]
        fragments = status_fragments(self.session, waveforms=self.top == "waves")
        style, text, *_ = fragments[-1]
        return [*fragments[:-1], (style, text.rstrip("\n"))]  # no blank line under it

    def _rule(self) -> str:
        back = self.log.back
        if back:
            return f"── {back} lines back · PgUp/PgDn scroll · End: newest ".ljust(WIDTH, "─")
        return "─" * WIDTH

    # ------------------------------------------------------------ running

    async def run(self) -> None:
        """Run until quit; the link is read every REFRESH seconds."""
        app, session = self.app, self.session

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
                        text = _shown(session)
                        if text != shown:
                            shown = text
                            app.invalidate()
                    await asyncio.sleep(REFRESH)
            except Exception as exc:
                app.exit(exception=exc)

        def start_ticker() -> None:
            app.create_background_task(ticker())

        def quit_app() -> None:
            if app.is_running and app.future is not None and not app.future.done():
                app.exit()

        # An ending signal asks the loop to quit (run_drive then stops the car); the
        # loop's own signal handlers are not used: removing them restores the default
        # action (a SIGHUP would then kill the process before its `Z`), and Windows has
        # none.
        loop = asyncio.get_running_loop()

        def on_signal() -> None:
            loop.call_soon_threadsafe(quit_app)

        with signals.diverted(on_signal):
            await app.run_async(pre_run=start_ticker, handle_sigint=False)


def _shown(session: BaseSession) -> str:
    """What the panel and the messages show, as text (to tell whether to draw again)."""
    panel = "".join(fragment[1] for fragment in status_fragments(session))
    return panel + "\n".join(session.messages)


def _completer(session: BaseSession) -> NestedCompleter:
    return NestedCompleter.from_nested_dict(session.completions)


def is_quit(text: str) -> bool:
    return text.strip().lower() in QUIT_WORDS


def command_history() -> History:
    """The commands typed, kept across sessions in the user's data folder (in memory
    when that cannot be written)."""
    folder = data_folder()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / "history"
        os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600))
        os.chmod(path, 0o600)  # what was typed is the user's own (older copies: 0644)
    except OSError:
        return InMemoryHistory()
    return FileHistory(str(path))
