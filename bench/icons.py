"""Draw the page's icons: `python bench/icons.py appmode/web/static` writes icon.svg and,
from the same shapes, icon-192.png and icon-512.png (a home screen and a splash screen
take PNG). The shapes sit inside the middle 80 % so a maskable icon's circle keeps them."""

from __future__ import annotations

import struct
import sys
import zlib
from pathlib import Path

BLUE, NAVY, WHITE = (0x15, 0x65, 0xC0), (0x0D, 0x2B, 0x52), (0xFF, 0xFF, 0xFF)
# (kind, geometry, colour), painted in order on a 512 x 512 canvas
SHAPES = (
    ("rect", (0, 0, 512, 512, 96), BLUE),
    ("rect", (176, 140, 160, 90, 24), WHITE),
    ("rect", (96, 200, 320, 120, 28), WHITE),
    ("circle", (176, 330, 46), NAVY),
    ("circle", (336, 330, 46), NAVY),
    ("circle", (176, 330, 16), WHITE),
    ("circle", (336, 330, 16), WHITE),
)


def _hex(colour: tuple[int, int, int]) -> str:
    return "#%02x%02x%02x" % colour


def svg() -> str:
    parts = []
    for kind, g, colour in SHAPES:
        if kind == "rect":
            x, y, w, h, r = g
            parts.append(f'<rect x="{x}" y="{y}" width="{w}" height="{h}" rx="{r}" fill="{_hex(colour)}"/>')
        else:
            cx, cy, r = g
            parts.append(f'<circle cx="{cx}" cy="{cy}" r="{r}" fill="{_hex(colour)}"/>')
    body = "".join(parts)
    return f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 512 512">{body}</svg>\n'


def _inside(kind: str, g: tuple[int, ...], x: float, y: float) -> bool:
    if kind == "circle":
        cx, cy, r = g
        return (x - cx) ** 2 + (y - cy) ** 2 <= r * r
    rx, ry, w, h, r = g
    if not (rx <= x <= rx + w and ry <= y <= ry + h):
        return False
    nx = min(max(x, rx + r), rx + w - r)  # the nearest point of the inner rectangle
    ny = min(max(y, ry + r), ry + h - r)
    return (x - nx) ** 2 + (y - ny) ** 2 <= r * r


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
                    for kind, g, colour in SHAPES:
                        if _inside(kind, g, x, y):
                            found = colour
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
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

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
