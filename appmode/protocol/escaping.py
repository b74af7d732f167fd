"""Bytes as printable text, losslessly (transcript format v1, docs/design.md).

Bytes 0x21–0x7E stand for themselves, except the backslash, written `\\\\`; every
other byte is written `\\xNN`.
"""

from __future__ import annotations

from appmode.patterns import deferred

_TABLE = [chr(b) if 0x21 <= b <= 0x7E else f"\\x{b:02x}" for b in range(256)]
_TABLE[0x5C] = "\\\\"
_TEXT_TABLE = {b: text for b, text in enumerate(_TABLE) if text != chr(b)}
_PLAIN = deferred(rb"[\x21-\x5b\x5d-\x7e]*")
_TOKEN = deferred(r"\\(?:x([0-9a-fA-F]{2})|(\\))|([\x21-\x5b\x5d-\x7e])")
_NOT_TEXT = deferred(rb"[^\x20-\x7e\t\r\n]")


def text_part(data: bytes) -> bytes:
    """The bytes of `data` a person reads as text: printable ASCII, tabs and line ends."""
    return _NOT_TEXT.sub(b"", data)


def escape(data: bytes) -> str:
    """`data` as printable ASCII."""
    if _PLAIN.fullmatch(data):  # the common case: it stands for itself
        return data.decode("ascii")
    return data.decode("latin-1").translate(_TEXT_TABLE)


def unescape(text: str) -> bytes:
    """The bytes `text` stands for; ValueError names the first column that is wrong."""
    out = bytearray()
    pos = 0
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if match is None:
            char = text[pos]
            hint = "write a backslash as \\\\ and other bytes as \\xNN"
            raise ValueError(f"column {pos + 1}: {char!r} cannot stand for itself; {hint}")
        hexa, backslash, plain = match.groups()
        if hexa is not None:
            out.append(int(hexa, 16))
        elif backslash is not None:
            out.append(0x5C)
        else:
            out += plain.encode("ascii")
        pos = match.end()
    return bytes(out)
