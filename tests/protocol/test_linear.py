"""Every decoder runs in time linear in its input, whatever the input holds: a capture at
the wrong baud rate is all garbage. The bound is generous (a quadratic decoder takes
minutes on these inputs, a linear one well under a second); bench/decoder.py measures."""

from __future__ import annotations

import random
import time

import pytest

from appmode.protocol.app import Garbage, Noise
from appmode.protocol.app_decoders import BoardDecoder, HostDecoder
from appmode.protocol.render import MAX_RUN, coalesce

SIZE = 1_000_000
BOUND = 20.0  # seconds, for a megabyte
INPUTS = {
    "random": random.Random(5).randbytes(SIZE),
    "braces": b"{" * SIZE,
    "digits": b"{A" + b"7" * SIZE,
    "record-prefixes": b"{A1:2:3" * (SIZE // 7),
}


@pytest.mark.parametrize("decoder", [BoardDecoder, HostDecoder])
@pytest.mark.parametrize("name", list(INPUTS))
def test_a_megabyte_of_garbage_decodes_within_a_generous_bound(
    decoder: type[BoardDecoder] | type[HostDecoder], name: str
) -> None:
    data = INPUTS[name]
    start = time.perf_counter()
    whole = decoder()
    events = [*whole.feed(data), *whole.flush()]
    elapsed = time.perf_counter() - start
    assert b"".join(e.raw for e in events) == data
    assert elapsed < BOUND, f"{name}: {elapsed:.1f} s for {len(data)} bytes"


def test_coalescing_a_long_run_is_linear() -> None:
    pieces = [Garbage(b"x")] * (2 * SIZE) + [Noise(b"q")] * 1000
    start = time.perf_counter()
    merged = list(coalesce(pieces))
    elapsed = time.perf_counter() - start
    assert b"".join(e.raw for e in merged) == b"x" * (2 * SIZE) + b"q" * 1000
    assert [type(e) for e in merged] == [Garbage] * -(-2 * SIZE // MAX_RUN) + [Noise]
    assert max(len(e.raw) for e in merged) == MAX_RUN  # bounded (issue 49.9)
    assert elapsed < BOUND


def test_conform_on_virtual_time_is_linear_in_what_the_transcript_sends() -> None:
    """Issue 22.7: 25,000 `>` lines sent faster than 9600 bps carries them took 26 s
    (every step re-read every line); a linear run takes well under a second."""
    from appmode.protocol.transcript import parse_transcript
    from appmode.transcript.runner import run_virtual

    lines = [f"{i * 0.0001:.4f} > AAAAAAAA" for i in range(25_000)]
    text = "\n".join(["# appmode transcript v1", *lines, "30.000 < {A*:*:*:*}$", ""])
    start = time.perf_counter()
    result = run_virtual(parse_transcript(text))
    elapsed = time.perf_counter() - start
    assert result.passed, result.failure
    assert elapsed < BOUND / 2, f"{elapsed:.1f} s for 25,000 lines"
