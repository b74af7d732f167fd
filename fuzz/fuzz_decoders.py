"""Coverage-guided fuzzing of the decoders (atheris): pip install atheris, then

    python fuzz/fuzz_decoders.py -atheris_runs=2000000

Each input is fed to both decoders whole and split at a point the input chooses. A
decoder must never raise, must hold at most LIMIT bytes, must give every byte to one
event, and must give the same events however the stream is split.
"""

from __future__ import annotations

import contextlib
import sys

import atheris

with atheris.instrument_imports():
    from appmode.protocol.app import BoardDecoder, HostDecoder
    from appmode.protocol.transcript import TranscriptError, parse_transcript


def check(make: type[HostDecoder] | type[BoardDecoder], data: bytes, cut: int) -> None:
    whole = make()
    events = [*whole.feed(data), *whole.flush()]
    split = make()
    pieces = split.feed(data[:cut])
    assert split.buffered <= make.LIMIT
    pieces += split.feed(data[cut:])
    assert split.buffered <= make.LIMIT
    pieces += split.flush()
    assert pieces == events, (data, cut)
    assert b"".join(e.raw for e in events) == data


def test_one_input(payload: bytes) -> None:
    if not payload:
        return
    cut, data = payload[0] % (len(payload)), payload[1:]
    check(HostDecoder, data, min(cut, len(data)))
    check(BoardDecoder, data, min(cut, len(data)))
    with contextlib.suppress(TranscriptError):
        parse_transcript(data.decode("utf-8", "replace"), "fuzz.transcript")


def main() -> None:
    atheris.Setup(sys.argv, test_one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
