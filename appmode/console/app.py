"""`appmode drive`: the full-screen console, and its script mode for stdin that is no TTY.

A prompt_toolkit Application (not a PromptSession, which would take the arrow keys for
history): the status panel, the 3×3 key grid and arrows to drive, and a command line
(`:`) with completion and history. Whatever ends it, the session's close sends `Z` last.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import sys
import time
from collections.abc import Iterable
from typing import TextIO

from prompt_toolkit.application import Application
from prompt_toolkit.buffer import Buffer
from prompt_toolkit.completion import NestedCompleter
from prompt_toolkit.data_structures import Point
from prompt_toolkit.filters import Condition
from prompt_toolkit.history import FileHistory, History, InMemoryHistory
from prompt_toolkit.input import Input
from prompt_toolkit.key_binding import KeyBindings, KeyPressEvent
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
from prompt_toolkit.layout.dimension import Dimension
from prompt_toolkit.layout.menus import CompletionsMenu
from prompt_toolkit.output import Output

from appmode.console.panel import status_fragments, status_text
from appmode.console.panel_parts import ARROWS, KEY_GRID, Fragments
from appmode.files import data_folder
from appmode.host import signals
from appmode.host.tokens import Wait
from appmode.session.base import LOG, QUIT_WORDS, BaseSession, Quit, ShowHelp, ShowStatus, Step
from appmode.session.status import WIDTH
from appmode.text import wrapped

REFRESH = 0.02
"""Seconds between reads of the link (and checks of the hold-to-drive timers)."""
MESSAGES = 8
"""Message lines shown when the terminal's height cannot be known."""
REDRAW = 0.1
"""How often the panel is checked, and redrawn if what it shows changed (a key redraws at
once)."""

HELP_TITLE = "help · ? or Esc close · PgUp/PgDn scroll"
NO_WAVES = (
    "no waveforms on the control port's console: they plot the APP port's A and B "
    "records (appmode drive APP_URL)"
)


def _completer(session: BaseSession) -> NestedCompleter:
    table: dict[str, object] = dict.fromkeys(session.command_names)
    table.update(latch={"on": None, "off": None}, record={"stop": None}, **session.completions)
    return NestedCompleter.from_nested_dict(table)


def build_app(
    session: BaseSession,
    input: Input | None = None,
    output: Output | None = None,
    history: History | None = None,
) -> Application[None]:
    """The console's Application over a started session."""
    # Completions show on Tab only, not while typing.
    command = Buffer(
        multiline=False,
        completer=_completer(session),
        history=history or InMemoryHistory(),
        complete_while_typing=False,
    )
    warned = False

    def leave(app: Application[None]) -> None:
        """Quit; the first time, if parameters were set and not saved, only say so."""
        nonlocal warned
        warning = session.unsaved_warning()
        if warning is not None and not warned:
            warned = True
            session.say(f"{warning} — :save keeps it; quit again to leave")
            return
        app.exit()

    view = View()
    status = Window(
        FormattedTextControl(lambda: _top(session, view), focusable=True),
        wrap_lines=False,
        dont_extend_height=True,
    )

    def log_lines() -> list[str]:
        """The messages in lines of the window's width, words whole."""
        width = messages.render_info.window_width if messages.render_info else WIDTH
        return [part for text in session.messages for part in _lines(text, width)]

    def shown() -> list[str]:
        """The log up to its newest line, or to `view.back` lines before it."""
        log = log_lines()
        return log[: len(log) - view.back]

    def bottom() -> Point:  # the window follows this point: the end of what is shown
        log = shown()
        return Point(len(log[-1]) if log else 0, max(0, len(log) - 1))

    messages = Window(
        FormattedTextControl(lambda: "\n".join(shown()), get_cursor_position=bottom),
        height=Dimension(min=3, preferred=3),  # the panel first, the log in what is left
        wrap_lines=True,
        always_hide_cursor=True,
    )
    rule = Window(FormattedTextControl(lambda: _rule(view)), height=1, style="fg:ansibrightblack")
    command_line = VSplit(
        [Window(FormattedTextControl(":"), width=1), Window(BufferControl(command), height=1)]
    )
    typing = Condition(lambda: app.layout.has_focus(command))
    driving = ~typing
    keys = KeyBindings()

    def drive_key(row: int, col: int) -> None:
        session.press(session.grid_key(row, col))

    for r, row in enumerate(KEY_GRID):
        for c, key in enumerate(row):
            keys.add(key, filter=driving)(lambda e, r=r, c=c: drive_key(r, c))
            keys.add(key.upper(), filter=driving)(lambda e, r=r, c=c: drive_key(r, c))
    for arrow, (r, c) in ARROWS.items():
        keys.add(arrow, filter=driving)(lambda e, r=r, c=c: drive_key(r, c))
    for key, what in session.hold_keys.items():
        keys.add(key, filter=driving)(lambda e, what=what: session.press(what))
    keys.add(" ", filter=driving)(lambda e: session.stop())
    for key, line in session.keys.items():
        keys.add(key, filter=driving)(lambda e, line=line: _key_command(session, line))
    keys.add("l", filter=driving)(
        lambda e: session.run("latch off" if session.driving.latched else "latch on")
    )
    keys.add("?", filter=driving)(lambda e: view.toggle("help"))
    if session.waveforms:
        keys.add("v", filter=driving)(lambda e: view.toggle("waves"))
    else:
        keys.add("v", filter=driving)(lambda e: session.say(NO_WAVES))
    keys.add("escape", filter=driving & Condition(lambda: view.top != "panel"))(
        lambda e: view.toggle(view.top)
    )

    def scroll(lines: int) -> None:
        if view.top == "help":  # the help scrolls, not the messages under it
            shown = status.render_info.window_height if status.render_info else MESSAGES
            last = max(0, len(session.help_lines()) + 1 - shown)
            view.help_first = min(last, max(0, view.help_first - max(1, shown - 1) * lines))
            return
        height = messages.render_info.window_height if messages.render_info else MESSAGES
        step = max(1, height - 1) * lines
        oldest = max(0, len(log_lines()) - height)  # the first page, full
        view.back = min(oldest, max(0, view.back + step))

    keys.add("pageup")(lambda e: scroll(1))
    keys.add("pagedown")(lambda e: scroll(-1))
    keys.add("end", filter=driving)(lambda e: setattr(view, "back", 0))

    @keys.add(":", filter=driving)
    def _command(event: KeyPressEvent) -> None:
        session.stop()  # the keys stop driving while typing: never leave the car moving
        event.app.layout.focus(command)

    @keys.add("escape", filter=typing, eager=True)
    def _leave(event: KeyPressEvent) -> None:
        command.reset()
        event.app.layout.focus(status)

    # While typing, ↑ and ↓ walk the history, never a completion menu (Tab and Shift-Tab
    # do): `:`, Tab, ↑ used to pick the menu's last entry, `quit`.
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
        if not is_quit(text):  # never one ↑ and Enter away
            command.append_to_history()
        command.reset()
        event.app.layout.focus(status)
        try:
            step = session.run(text)
        except Quit:
            leave(event.app)
            return
        if isinstance(step, Wait):
            session.say("wait is for script mode")
        elif isinstance(step, ShowHelp):
            view.top = "help"  # the whole of it, in place of the panel
        else:
            _show(session, step)

    keys.add("c-c")(lambda e: e.app.exit())  # at once: the session's close says what
    keys.add("c-q")(lambda e: leave(e.app))

    layout = Layout(
        FloatContainer(
            HSplit(
                [
                    status,
                    rule,
                    messages,
                    ConditionalContainer(command_line, filter=typing),
                ]
            ),
            floats=[Float(xcursor=True, ycursor=True, content=CompletionsMenu(max_height=8))],
        ),
        focused_element=status,
    )
    app: Application[None] = Application(
        layout=layout, key_bindings=keys, full_screen=True, input=input, output=output
    )
    return app


@functools.lru_cache(maxsize=2 * LOG)
def _lines(text: str, width: int) -> tuple[str, ...]:
    """A message in lines of `width` columns, words whole (each is wrapped once: the
    log is drawn many times a second while a key is held)."""
    return tuple(wrapped(text, width).split("\n"))


def _key_command(session: BaseSession, line: str) -> None:
    """A key that runs a command line; a quit from it would be a surprise: none do."""
    with contextlib.suppress(Quit):
        session.run(line)


class View:
    """What the console shows above its messages, and how far back they are scrolled."""

    def __init__(self) -> None:
        self.top = "panel"
        """"panel", "waves" (the panel with waveforms) or "help"."""
        self.back = 0
        """Message lines scrolled back from the newest (PageUp / PageDown)."""
        self.help_first = 0
        """The first line of the help shown (PageUp / PageDown while it is shown)."""

    def toggle(self, name: str) -> None:
        self.top = "panel" if self.top == name else name
        self.help_first = 0


def _top(session: BaseSession, view: View) -> Fragments:
    if view.top == "help":
        lines = [HELP_TITLE, *session.help_lines()][view.help_first :]
        return [("", "\n".join(lines))]
    fragments = status_fragments(session, waveforms=view.top == "waves")
    style, text, *_ = fragments[-1]
    return [*fragments[:-1], (style, text.rstrip("\n"))]  # no blank line under it


def _rule(view: View) -> str:
    if view.back:
        return f"── {view.back} lines back · PgUp/PgDn scroll · End: newest ".ljust(WIDTH, "─")
    return "─" * WIDTH


async def run_app(app: Application[None], session: BaseSession) -> None:
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

    def quit_app() -> None:
        if app.is_running and app.future is not None and not app.future.done():
            app.exit()

    # An ending signal asks the loop to quit (run_drive then stops the car); the loop's
    # own signal handlers are not used: removing them restores the default action (a
    # SIGHUP would then kill the process before its `Z`), and Windows has none.
    loop = asyncio.get_running_loop()

    def on_signal() -> None:
        loop.call_soon_threadsafe(quit_app)

    with signals.diverted(on_signal):
        await app.run_async(pre_run=start_ticker, handle_sigint=False)


def run_drive(
    session: BaseSession,
    interactive: bool,
    script: Iterable[str],
    out: TextIO,
    input: Input | None = None,
    output: Output | None = None,
    keep_going: bool = False,
) -> int:
    """Start the session, run the console (or script mode), and always close it: `Z` last.
    Parameters set and not saved are named at the end. Script mode ends at the first
    error (every line with `keep_going`); its exit status is 1 if any line failed."""
    try:
        session.start()
        if interactive:
            app = build_app(session, input, output, command_history())
            asyncio.run(run_app(app, session))
        else:
            run_script(session, script, out, keep_going)
    finally:
        warning = session.unsaved_warning()
        try:
            session.close()
        finally:
            for note in session.closing_notes:
                print(f"appmode: WARNING: {note}", file=sys.stderr)
            if warning is not None:
                lasts = (
                    "the embedded board ends with this session"
                    if session.simulated
                    else "the board keeps it until it is switched off"
                )
                print(f"appmode: {warning}: {lasts}", file=sys.stderr)
    return 1 if session.failures and not interactive else 0


def is_quit(text: str) -> bool:
    return text.strip().lower() in QUIT_WORDS


def command_history() -> History:
    """The commands typed, kept across sessions in the user's data folder (in memory
    when that cannot be written)."""
    folder = data_folder()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / "history"
        path.touch()
    except OSError:
        return InMemoryHistory()
    return FileHistory(str(path))


def run_script(
    session: BaseSession, lines: Iterable[str], out: TextIO, keep_going: bool = False
) -> None:
    """Script mode: run commands line by line; `wait S` lets S seconds pass.

    A parameter read or set finishes before the next line runs. The first error ends
    the script, unless `keep_going`.
    """
    _settle(session, 0.0)
    for raw in lines:
        if session.failures and not keep_going:
            print(
                "appmode: the script stopped at its first error (--keep-going runs on)",
                file=sys.stderr,
            )
            break
        try:
            step = session.run(raw)
        except Quit:
            break  # run_drive names what was not saved
        _show(session, step)
        _settle(session, step.seconds if isinstance(step, Wait) else 0.0)
    out.flush()


def _show(session: BaseSession, step: Step) -> None:
    """What a command returned for the view: the panel for `status`, the help for
    `help`, as messages."""
    if isinstance(step, ShowStatus):
        session.say(status_text(session))
    elif isinstance(step, ShowHelp):
        for text in session.help_lines():
            session.say(text)


def _settle(session: BaseSession, seconds: float) -> None:
    """Let `seconds` pass, and any parameter query end, reading the link meanwhile."""
    end = time.monotonic() + seconds
    session.tick()
    while time.monotonic() < end or session.busy:
        time.sleep(min(REFRESH, max(0.0, end - time.monotonic())) or REFRESH)
        session.tick()
