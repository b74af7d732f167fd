"""The drive letters, the two pages and what each letter means per drive type (§2.1, §4).

One table: the codec reads the letters, the board reads the motions, the console reads
the grid. A motion is given as unit factors of S (parameter 0, max speed).
"""

from __future__ import annotations

from collections.abc import Mapping
from enum import Enum

from appmode.protocol import profile_file
from appmode.protocol.slotted import Frozen

LETTERS = "ABCDEFGH"
"""Direction 1…8 is LETTERS[n - 1]; the same byte values 0x01…0x08 are accepted raw."""


class Page(Enum):
    """The app page the board is on: I/J select the direction page, K the button page."""

    DIRECTION = "direction"
    BUTTON = "button"


PAGE_LETTERS: dict[str, Page] = {"I": Page.DIRECTION, "J": Page.DIRECTION, "K": Page.BUTTON}
PAGE_NAMES: dict[str, str] = dict(profile_file.shipped("sheet").pages)
"""The app's page each letter switches to, as the sheet's profile file names them."""
STOP_LETTER = "Z"


class Motion(Frozen):
    """A physical motion: omni/mecanum factors (x, y, z) and differential factors (y, z)."""

    __slots__ = _fields = _shown = ("name", "holonomic", "differential")
    name: str
    holonomic: tuple[float, float, float]
    differential: tuple[float, float]

    def __init__(
        self, name: str, holonomic: tuple[float, float, float], differential: tuple[float, float]
    ) -> None:
        self._fill(name, holonomic, differential)


_MOTIONS = (
    Motion("forward", (0, 1, 0), (1, 0)),
    Motion("front-right", (1, 1, 0), (1, 0.5)),
    Motion("right", (1, 0, 0), (0, 1)),
    Motion("rear-right", (1, -1, 0), (-1, -0.5)),
    Motion("backward", (0, -1, 0), (-1, 0)),
    Motion("rear-left", (-1, -1, 0), (-1, 0.5)),
    Motion("left", (-1, 0, 0), (0, -1)),
    Motion("front-left", (-1, 1, 0), (1, -0.5)),
    Motion("rotate-cw", (0, 0, 1), (0, 1)),
    Motion("rotate-ccw", (0, 0, -1), (0, -1)),
)
MOTIONS: dict[str, Motion] = {m.name: m for m in _MOTIONS}

DIRECTION_PAGE: dict[str, Motion] = {
    letter: MOTIONS[name]
    for letter, name in zip(
        LETTERS,
        (
            "forward",
            "front-right",
            "right",
            "rear-right",
            "backward",
            "rear-left",
            "left",
            "front-left",
        ),
        strict=True,
    )
}
"""The 3×3 grid of the sheet: H A B / G Z C / F E D."""

BUTTON_PAGE: dict[str, Motion] = {
    "A": MOTIONS["forward"],
    "B": MOTIONS["front-left"],  # mirrored against the grid, as the sheet says (§4)
    "C": MOTIONS["rotate-cw"],
    "D": MOTIONS["rear-right"],
    "E": MOTIONS["backward"],
    "F": MOTIONS["rear-left"],
    "G": MOTIONS["rotate-ccw"],
    "H": MOTIONS["front-right"],
}

Grid = tuple[tuple[str, str, str], ...]
GRID: Grid = (("H", "A", "B"), ("G", "Z", "C"), ("F", "E", "D"))
"""The direction page's keys as laid out on the phone screen."""
BUTTON_GRID: Grid = (("B", "A", "H"), ("G", "Z", "C"), ("F", "E", "D"))
"""The button page's letters by where their motion points: front-left is B (§4)."""


def grid_for(page: Page) -> Grid:
    """The letters of a page laid out by direction of motion (row 0 = front)."""
    return GRID if page is Page.DIRECTION else BUTTON_GRID


def letter_name(page: Page, letter: str) -> str:
    """What a letter does on a page: 'forward', 'rotate-cw', 'stop'."""
    if letter == STOP_LETTER:
        return "stop"
    motion = motion_for(page, LETTERS.index(letter) + 1)
    assert motion is not None
    return motion.name


def motion_for(
    page: Page, direction: int, buttons: Mapping[str, Motion] = BUTTON_PAGE
) -> Motion | None:
    """The motion of direction 1…8 on `page`; None for 0 (stop) or a letter that is not
    one of `buttons` (the button page's letters, which depend on the board)."""
    if direction == 0:
        return None
    table = DIRECTION_PAGE if page is Page.DIRECTION else buttons
    return table.get(LETTERS[direction - 1])


def target_velocity(
    page: Page,
    direction: int,
    speed: float,
    differential: bool,
    buttons: Mapping[str, Motion] = BUTTON_PAGE,
) -> tuple[float, float, float]:
    """Target body velocity (x, y, z) for a direction at max speed `speed`."""
    motion = motion_for(page, direction, buttons)
    if motion is None:
        return (0.0, 0.0, 0.0)
    if differential:
        y, z = motion.differential
        return (0.0, y * speed, z * speed)
    x, y, z = motion.holonomic
    return (x * speed, y * speed, z * speed)
