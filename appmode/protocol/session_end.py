"""What ends a host's session with the car stopped, with no I/O (docs/protocol.md §2.1,
§13): a `Z` that no open frame swallows, and no rotation left running."""

from __future__ import annotations

from collections.abc import Collection

from appmode.protocol.app import HostEvent, Move, Noise, Stop, SwitchPage, encode
from appmode.protocol.app_decoders import HostDecoder
from appmode.protocol.directions import BUTTON_PAGE

ABANDON_FRAME = b"{}"
"""Ends an open frame without applying it: `{` abandons the open frame (§2.2) and `{}` is
an empty frame, which changes nothing."""


def stop_again(frames_take_letters: bool) -> bytes:
    """What to send when a stop did not take (the car still moves): where a frame takes
    letters (the sheet, §2.2) a frame another program left open may have swallowed the
    `Z`: `{` drops it unapplied and `}` closes the empty frame; `K` ends a button-page
    rotation left by `I`/`J` (§13) and `J` goes back to the direction page; then `Z`.
    Where every byte steers even inside a frame (the reference firmware, §13) no brace is
    sent: there a `}` would apply a half-sent set."""
    return (ABANDON_FRAME if frames_take_letters else b"") + b"KJ" + encode(Stop())


class SessionEnd:
    """Follows what a host sends, so that its last bytes stop the car (§2.1), and what
    the board was last told: the page, and the drive letter it still follows.

    A `Z` sent while a frame is open is swallowed by the frame: then `{}` goes first. A
    rotation begun on the button page and left by `I`/`J` goes on after `Z` on the
    reference firmware (§13): then `K` ends it, and the page letter goes back, first.
    `speed_keys`: a firmware's own speed letters (`X`), which change the speed, not the
    motion; `frames_stop`: every frame stops the car (the reference firmware's `{`).
    """

    def __init__(self, speed_keys: Collection[str] = (), frames_stop: bool = False) -> None:
        self._decoder = HostDecoder()
        self._page = "J"  # the page letter last sent (the board boots on the direction page)
        self._turning = False  # a button-page rotation that a direction-page Z leaves on
        self._speed_keys = speed_keys
        self._frames_stop = frames_stop
        self.letter: str | None = None
        """The drive letter the board was last sent and still follows; None: stopped."""

    def sent(self, data: bytes) -> list[HostEvent]:
        """Follow `data` (bytes that have left for the board); returns what it decodes to."""
        events = self._decoder.feed(data)
        for event in events:
            if isinstance(event, SwitchPage):
                self._turning = self._turning and event.letter != "K"
                self._page = event.letter
            elif self._page == "K" and isinstance(event, (Move, Stop, Noise)):
                self._turning = isinstance(event, Move) and _rotates(event)
            elif isinstance(event, Move):
                self._turning = False
            self._follow(event)
        return events

    def _follow(self, event: HostEvent) -> None:
        """The letter in force after `event` (§2.1: any other byte stops the car)."""
        if isinstance(event, Move):
            self.letter = event.letter
        elif (
            isinstance(event, (Stop, SwitchPage))
            or (isinstance(event, Noise) and event.raw.decode("latin-1") not in self._speed_keys)
            or (self._frames_stop and event.raw.startswith(b"{"))
        ):
            self.letter = None

    @property
    def page_letter(self) -> str:
        """The page letter last sent (`J` until one is)."""
        return self._page

    @property
    def moving(self) -> bool:
        """Whether the board was last told to move: a drive letter, or a button-page
        rotation that the direction page's `Z` leaves on (§13)."""
        return self.letter is not None or (self._turning and self._page != "K")

    @property
    def stop(self) -> bytes:
        """The bytes that end the session with the car stopped."""
        frame = ABANDON_FRAME if self._decoder.in_frame else b""
        rotation = f"K{self._page}".encode() if self._turning and self._page != "K" else b""
        return frame + rotation + encode(Stop())

    @property
    def stop_text(self) -> str:
        """What `stop` does, for people."""
        steps = ["closes the open frame"] if self._decoder.in_frame else []
        if self._turning and self._page != "K":
            steps.append(f"ends a button-page rotation (K), back to {self._page}")
        return ", ".join([*steps, "then stop"]) if steps else "stop"


def _rotates(move: Move) -> bool:
    """A button-page letter that rotates the car on the spot (C, G)."""
    motion = BUTTON_PAGE.get(move.letter)
    return not move.numeric and motion is not None and motion.holonomic[:2] == (0, 0)
