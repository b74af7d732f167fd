"""`appmode decode`: a raw byte stream in, JSON Lines out."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterable, Iterator

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_profile
from appmode.errors import AppmodeError

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:  # the codec is imported when the command runs: start-up stays short
    from typing import BinaryIO, TextIO

    from appmode.protocol import app
    from appmode.protocol.layouts import Layout

CHUNK = 65536


def decode_chunks(
    chunks: Iterable[bytes], source: str, layout: Layout | None = None
) -> Iterator[app.Event]:
    """Events of a stream from the host (`host`) or the board (`board`, its records as
    `layout` counts their fields; by default the sheet's)."""
    from appmode.protocol import app_decoders
    from appmode.protocol.layouts import VELOCITY

    decoder = (
        app_decoders.HostDecoder() if source == "host" else (layout or VELOCITY).board_decoder()
    )
    for chunk in chunks:
        yield from decoder.feed(chunk)
    yield from decoder.flush()


def read_chunks(stream: BinaryIO, name: str, out: TextIO) -> Iterator[bytes]:
    """Chunks as they arrive (a pipe from a live port is decoded as it goes): what was
    written is flushed before each read, so output keeps up without a flush a line."""
    read = getattr(stream, "read1", stream.read)
    while True:
        out.flush()
        try:
            chunk = read(CHUNK)
        except OSError as exc:
            raise AppmodeError(f"cannot read {name}: {exc.strerror}") from None
        if not chunk:
            return
        yield chunk


def run_decode(
    stream: BinaryIO,
    out: TextIO,
    source: str,
    name: str = "standard input",
    layout: Layout | None = None,
) -> int:
    """Write one JSON object a line (A records as `layout` reads them, by default the
    sheet's); returns the number of undecodable runs."""
    from appmode.protocol import app
    from appmode.protocol.layouts import VELOCITY
    from appmode.protocol.render import coalesce, json_line

    layout = layout or VELOCITY
    errors = 0
    write = out.write
    chunks = read_chunks(stream, name, out)
    for event in coalesce(decode_chunks(chunks, source, layout)):
        errors += isinstance(event, app.ERRORS)
        write(json_line(event, layout) + "\n")
    out.flush()
    return errors


def register(sub: Subparsers) -> argparse.ArgumentParser:
    decode = sub.add_parser(
        "decode",
        help=COMMANDS["decode"],
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
    add_profile(decode, default=None, unset="sheet")
    decode.add_argument(
        "--chassis",
        action="store_true",
        help="the bytes are a WHEELTEC chassis port's (7B … 7D frames at 115200 bps): "
        "velocity frames from the host, status frames from the board, in SI units",
    )
    return decode


def run_chassis(stream: BinaryIO, out: TextIO, source: str, name: str) -> int:
    """Write one JSON object a frame of a chassis port's bytes (and one a run of bytes
    that is no frame); returns the number of those runs."""
    import json

    from appmode.protocol import chassis

    decoder = chassis.CommandDecoder() if source == "host" else chassis.StatusDecoder()
    errors = 0

    def events() -> Iterator[chassis.Event]:
        for chunk in read_chunks(stream, name, out):  # as it comes: a live pipe too
            yield from decoder.feed(chunk)
        yield from decoder.flush()

    for event in events():
        errors += isinstance(event, chassis.Junk)
        out.write(json.dumps(chassis.as_json(event), ensure_ascii=False) + "\n")
    out.flush()
    return errors


def run(args: argparse.Namespace) -> int:
    if args.chassis and args.profile:
        raise AppmodeError("--profile names an APP port's records: leave it out with --chassis")
    if args.chassis:
        return _read(args, lambda stream, name: run_chassis(stream, sys.stdout, args.source, name))
    layout = None  # the sheet's
    if args.profile:
        from appmode.board.profiles import profile_named

        layout = profile_named(args.profile).a_layout
    return _read(
        args, lambda stream, name: run_decode(stream, sys.stdout, args.source, name, layout)
    )


def _read(args: argparse.Namespace, decode: Callable[[BinaryIO, str], int]) -> int:
    """`decode` the file the arguments name, or standard input."""
    if args.file in (None, "-"):
        decode(sys.stdin.buffer, "standard input")
        return 0
    try:
        stream = open(args.file, "rb")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise AppmodeError(f"cannot read {args.file}: {exc.strerror}") from None
    with stream:
        decode(stream, args.file)
    return 0
