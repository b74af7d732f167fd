"""appmode's decoders against their anchors, byte-at-a-time loops written the way the
firmware reads bytes (tests/support/byte_loops.py): on every kind of input, fed in any
chunks, they find the very events (bench/decoder.py times the same pairs)."""

from __future__ import annotations

import io

import pytest

from appmode.cli.decode import run_decode
from appmode.protocol.layouts import VELOCITY
from appmode.protocol.render import coalesce, json_line
from tests.support.byte_loops import SAME_EVENTS, SameEventsByteLoop, check_same_events, streams

INPUTS = streams(20_000)


@pytest.mark.parametrize("name", SAME_EVENTS)
@pytest.mark.parametrize("chunk", [1, 7, 4096])
def test_a_decoder_finds_what_its_byte_loop_finds(name: str, chunk: int) -> None:
    for data in INPUTS.values():
        check_same_events(name, data, chunk)


@pytest.mark.parametrize("what", ["APP board stream", "random bytes"])
def test_decode_writes_byte_for_byte_what_the_board_stream_s_loop_finds(what: str) -> None:
    """A board's stream, noisy or all noise (the loop joins a run of `{` and an
    unterminated record otherwise than the decoder splits them: it anchors streams)."""
    data = INPUTS[what]
    ours = io.StringIO()
    run_decode(io.BytesIO(data), ours, "board")
    loop = SameEventsByteLoop()
    loop.feed(data)
    loop.flush()
    theirs = "".join(json_line(event, VELOCITY) + "\n" for event in coalesce(loop.events))
    assert ours.getvalue() == theirs
