"""The console's message log: a read-only prompt_toolkit buffer of the session's
messages, words wrapped to the window, scrolled by its cursor (the last line shown)."""

from __future__ import annotations

import functools
from collections.abc import Sequence

from prompt_toolkit.buffer import Buffer
from prompt_toolkit.document import Document
from prompt_toolkit.layout import Window
from prompt_toolkit.layout.controls import BufferControl
from prompt_toolkit.layout.dimension import Dimension

from appmode.session.command_line import LOG
from appmode.session.rows import WIDTH
from appmode.text import wrapped

MESSAGES = 8
"""Message lines shown when the window's height is not known yet."""


@functools.lru_cache(maxsize=2 * LOG)
def _lines(text: str, width: int) -> tuple[str, ...]:
    """A message in lines of `width` columns, words whole (each is wrapped once: the
    log is drawn many times a second while a key is held)."""
    return tuple(wrapped(text, width).split("\n"))


class MessageLog:
    """The messages, newest at the bottom; PgUp/PgDn move back and forth, End goes to
    the newest, and new messages keep the place of a log scrolled back."""

    def __init__(self, messages: Sequence[str]) -> None:
        self.messages = messages
        self.buffer = Buffer(read_only=True)
        self.window = Window(
            BufferControl(self.buffer, focusable=False),
            height=Dimension(min=3, preferred=3),  # the panel first, the log in what is left
            get_vertical_scroll=self._first_shown,
            always_hide_cursor=True,
        )

    @property
    def height(self) -> int:
        info = self.window.render_info
        return info.window_height if info else MESSAGES

    @property
    def back(self) -> int:
        """Lines under the last one shown."""
        document = self.buffer.document
        return document.line_count - 1 - document.cursor_position_row

    def sync(self, _: object = None) -> None:
        """Take in new messages (before each render), keeping how far back it is."""
        info = self.window.render_info
        width = info.window_width if info else WIDTH
        text = "\n".join(part for message in self.messages for part in _lines(message, width))
        if text != self.buffer.text:
            self._show(Document(text), self.back)

    def scroll(self, pages: int) -> None:
        """Back (positive) or forward by pages; never past the first full page."""
        step = max(1, self.height - 1) * pages
        document = self.buffer.document
        oldest = max(0, document.line_count - self.height)
        self._show(document, min(oldest, max(0, self.back + step)))

    def newest(self) -> None:
        self._show(self.buffer.document, 0)

    def _show(self, document: Document, back: int) -> None:
        row = max(0, document.line_count - 1 - back)
        at = document.translate_row_col_to_index(row, 0)
        self.buffer.set_document(Document(document.text, at), bypass_readonly=True)

    def _first_shown(self, window: Window) -> int:
        """The window's top line: the cursor's line is its last."""
        return max(0, self.buffer.document.cursor_position_row - self.height + 1)
