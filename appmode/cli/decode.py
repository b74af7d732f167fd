"""`appmode decode`: a raw byte stream in, JSON Lines out."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterable, Iterator
from typing import BinaryIO, TextIO

from appmode.cli.options import Subparsers
from appmode.errors import AppmodeError
from appmode.protocol import app
from appmode.protocol.render import coalesce, to_json

CHUNK = 65536


def decode_chunks(chunks: Iterable[bytes], source: str) -> Iterator[app.Event]:
    """Events of a stream from the host (`host`) or the board (`board`)."""
    decoder = app.HostDecoder() if source == "host" else app.BoardDecoder()
    for chunk in chunks:
        yield from decoder.feed(chunk)
    yield from decoder.flush()


def read_chunks(stream: BinaryIO) -> Iterator[bytes]:
    """Chunks as they arrive (a pipe from a live port is decoded as it goes)."""
    read = getattr(stream, "read1", stream.read)
    while chunk := read(CHUNK):
        yield chunk


def run_decode(stream: BinaryIO, out: TextIO, source: str) -> int:
    """Write one JSON object a line; returns the number of undecodable runs."""
    errors = 0
    for event in coalesce(decode_chunks(read_chunks(stream), source)):
        errors += isinstance(event, app.ERRORS)
        out.write(json.dumps(to_json(event), ensure_ascii=False) + "\n")
        out.flush()
    return errors


def register(sub: Subparsers) -> argparse.ArgumentParser:
    decode = sub.add_parser(
        "decode",
        help="decode a raw byte stream to JSON Lines",
        description="Decode raw bytes (a capture of the serial line) to JSON Lines: one "
        "object per record or command, and one per undecodable run of bytes.",
    )
    decode.add_argument("file", nargs="?", help="file to read (default: standard input)")
    decode.add_argument(
        "--from",
        dest="source",
        choices=("host", "board"),
        default="board",
        help="who sent the bytes (default: board, i.e. board→host records)",
    )
    return decode


def run(args: argparse.Namespace) -> int:
    if args.file in (None, "-"):
        run_decode(sys.stdin.buffer, sys.stdout, args.source)
        return 0
    try:
        with open(args.file, "rb") as stream:
            run_decode(stream, sys.stdout, args.source)
    except OSError as exc:
        raise AppmodeError(f"cannot read {args.file}: {exc.strerror}") from None
    return 0
