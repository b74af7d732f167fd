"""Coverage-guided fuzzing of the decoders (atheris): pip install atheris, then

    python fuzz/fuzz_decoders.py -atheris_runs=2000000

Each input is fed to every decoder of both ports (the APP port's two; UART2's frame
decoder for each drive type, and its reply decoder for 3 and 4 wheels and in APP mode)
whole and split at a point the input chooses. A decoder must never raise, must hold at
most its limit, must give every byte to one event, and must give the same events
however the stream is split. The input is read as a transcript too.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable
from functools import partial

import atheris

with atheris.instrument_imports():
    from appmode.protocol.app_decoders import BoardDecoder, HostDecoder
    from appmode.protocol.control_decoders import FrameDecoder, ReplyDecoder
    from appmode.protocol.params import DriveType
    from appmode.protocol.transcript import TranscriptError, parse_transcript

Decoder = HostDecoder | BoardDecoder | FrameDecoder | ReplyDecoder
DECODERS: list[Callable[[], Decoder]] = [
    HostDecoder,
    BoardDecoder,
    *(partial(FrameDecoder, drive) for drive in DriveType),
    partial(ReplyDecoder, 3),
    partial(ReplyDecoder, 4),
    partial(ReplyDecoder, app_mode=True),
]


def limit(decoder: Decoder) -> int:
    """The most bytes `decoder` may hold."""
    return decoder.limit if isinstance(decoder, ReplyDecoder) else decoder.LIMIT


def check(make: Callable[[], Decoder], data: bytes, cut: int) -> None:
    whole = make()
    events = [*whole.feed(data), *whole.flush()]
    split = make()
    pieces = split.feed(data[:cut])
    assert split.buffered <= limit(split)
    pieces += split.feed(data[cut:])
    assert split.buffered <= limit(split)
    pieces += split.flush()
    assert pieces == events, (data, cut)
    assert b"".join(e.raw for e in events) == data


def test_one_input(payload: bytes) -> None:
    if not payload:
        return
    cut, data = payload[0] % (len(payload)), payload[1:]
    for make in DECODERS:
        check(make, data, min(cut, len(data)))
    with contextlib.suppress(TranscriptError):
        parse_transcript(data.decode("utf-8", "replace"), "fuzz.transcript")


def main() -> None:
    atheris.Setup(sys.argv, test_one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
