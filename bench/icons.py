"""Draw the page's icons: `python -m bench.icons appmode/web/static` writes icon.svg and,
from the same shapes, icon-192.png and icon-512.png (a home screen and a splash screen
take PNG). The shapes sit inside the middle 80 % so a maskable icon's circle keeps them."""

from __future__ import annotations

import struct
import sys
import zlib
from pathlib import Path
from typing import NamedTuple

Colour = tuple[int, int, int]
BLUE, NAVY, WHITE = (0x15, 0x65, 0xC0), (0x0D, 0x2B, 0x52), (0xFF, 0xFF, 0xFF)


class Rect(NamedTuple):
    x: int
    y: int
    w: int
    h: int
    r: int
    colour: Colour

    def svg(self) -> str:
        return (
            f'<rect x="{self.x}" y="{self.y}" width="{self.w}" height="{self.h}" '
            f'rx="{self.r}" fill="{_hex(self.colour)}"/>'
        )

    def covers(self, x: float, y: float) -> bool:
        if not (self.x <= x <= self.x + self.w and self.y <= y <= self.y + self.h):
            return False
        nx = min(max(x, self.x + self.r), self.x + self.w - self.r)  # nearest inner point
        ny = min(max(y, self.y + self.r), self.y + self.h - self.r)
        return (x - nx) ** 2 + (y - ny) ** 2 <= self.r**2


class Circle(NamedTuple):
    cx: int
    cy: int
    r: int
    colour: Colour

    def svg(self) -> str:
        return f'<circle cx="{self.cx}" cy="{self.cy}" r="{self.r}" fill="{_hex(self.colour)}"/>'

    def covers(self, x: float, y: float) -> bool:
        return (x - self.cx) ** 2 + (y - self.cy) ** 2 <= self.r**2


SHAPES: tuple[Rect | Circle, ...] = (  # painted in order on a 512 x 512 canvas
    Rect(0, 0, 512, 512, 96, BLUE),
    Rect(176, 140, 160, 90, 24, WHITE),
    Rect(96, 200, 320, 120, 28, WHITE),
    Circle(176, 330, 46, NAVY),
    Circle(336, 330, 46, NAVY),
    Circle(176, 330, 16, WHITE),
    Circle(336, 330, 16, WHITE),
)


def _hex(colour: Colour) -> str:
    return "#" + "".join(f"{c:02x}" for c in colour)


def svg() -> str:
    body = "".join(shape.svg() for shape in SHAPES)
    return f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 512 512">{body}</svg>\n'


def png(size: int, samples: int = 3) -> bytes:
    scale = 512 / size
    rows = []
    for py in range(size):
        row = bytearray([0])  # no filter
        for px in range(size):
            total = [0, 0, 0, 0]
            for sy in range(samples):
                for sx in range(samples):
                    x = (px + (sx + 0.5) / samples) * scale
                    y = (py + (sy + 0.5) / samples) * scale
                    found = None
                    for shape in SHAPES:
                        if shape.covers(x, y):
                            found = shape.colour
                    if found is not None:
                        total[0] += found[0]
                        total[1] += found[1]
                        total[2] += found[2]
                        total[3] += 255
            n = samples * samples
            alpha = total[3] // n
            cover = max(1, total[3] // 255)
            row += bytes([total[0] // cover, total[1] // cover, total[2] // cover, alpha])
        rows.append(bytes(row))

    def chunk(kind: bytes, data: bytes) -> bytes:
        check = struct.pack(">I", zlib.crc32(kind + data))
        return struct.pack(">I", len(data)) + kind + data + check

    header = struct.pack(">IIBBBBB", size, size, 8, 6, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(b"".join(rows), 9))
        + chunk(b"IEND", b"")
    )


def main(folder: str) -> None:
    out = Path(folder)
    (out / "icon.svg").write_text(svg(), encoding="utf-8")
    for size in (192, 512):
        (out / f"icon-{size}.png").write_bytes(png(size))


if __name__ == "__main__":
    main(sys.argv[1])
