"""Transcript format v1 (docs/design.md): writer and reader, and bad input with file:line."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from appmode.errors import AppmodeError
from appmode.protocol.recorder import Recorder
from appmode.protocol.transcript import (
    HEADER,
    MAX_LINE,
    Directive,
    TranscriptError,
    parse_transcript,
)
from appmode.transcript.reading import read_transcript


def test_recorder_writes_one_unit_a_line_and_escapes_bytes() -> None:
    out = io.StringIO()
    recorder = Recorder(out, directives=("board drive=diff",))
    recorder(">", 0.0, b"JA{Q:")
    recorder(">", 0.01, b"P}\r\n")
    recorder("<", 0.05, b"{A0:0:0:0}${B0:0")
    recorder("<", 0.06, b":0:100}$xx\\")
    recorder.close()
    assert out.getvalue().splitlines() == [
        HEADER,
        "@board drive=diff",
        "0.0000 > J",
        "0.0000 > A",
        "0.0000 > {Q:P}",  # a line carries the time of its first byte (issue 22.12)
        "0.0100 > \\x0d",
        "0.0100 > \\x0a",
        "0.0500 < {A0:0:0:0}$",
        "0.0500 < {B0:0:0:100}$",
        "0.0600 < xx\\\\",
    ]


def test_a_note_is_a_comment_in_time_order_after_the_units_before_it() -> None:
    out = io.StringIO()
    recorder = Recorder(out)
    recorder.note("tap: pty <-> sim://", 0.0)
    recorder(">", 0.1, b"A{1:")  # a frame open when the note comes: it waits for its end
    recorder.note("the app side\nleft", 0.2)  # one line, whatever it is given
    recorder(">", 0.3, b"}Z")
    recorder.close()
    assert out.getvalue().splitlines() == [
        HEADER,
        "# tap: pty <-> sim://",
        "0.1000 > A",
        "0.1000 > {1:}",
        "# the app side left",
        "0.3000 > Z",
    ]
    transcript = parse_transcript(out.getvalue())
    assert transcript.title == "tap: pty <-> sim://"
    assert b"".join(e.data for e in transcript.entries) == b"A{1:}Z"


def test_concatenated_payloads_give_back_the_exact_bytes() -> None:
    stream = bytes(range(256)) + b"{A1:2:3:0}${C1:2}$"
    out = io.StringIO()
    recorder = Recorder(out)
    recorder("<", 0.0, stream)
    recorder.close()
    transcript = parse_transcript(out.getvalue())
    assert b"".join(e.data for e in transcript.entries) == stream


def test_reader_keeps_title_directives_and_entries(tmp_path: Path) -> None:
    path = tmp_path / "t.transcript"
    path.write_text(
        f"{HEADER}\n# checks the C slot\n\n@tolerance 0.2\n0.100 > {{Q:P}}\n"
        "0.150 < {C*:*:*:*:*:*:*:*:*}$\n"
    )
    transcript = read_transcript(path)
    assert transcript.title == "checks the C slot"
    assert transcript.items[0] == Directive(4, "tolerance", ("0.2",))
    assert [(e.lineno, e.time, e.direction, e.data) for e in transcript.entries] == [
        (5, 0.1, ">", b"{Q:P}"),
        (6, 0.15, "<", b"{C*:*:*:*:*:*:*:*:*}$"),
    ]


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("0.1 > ", "expected 'TIME DIR PAYLOAD'"),
        ("0.1>{Q:P}", "expected 'TIME DIR PAYLOAD'"),
        ("soon > A", "time 'soon' is not seconds >= 0"),
        ("-1 > A", "time '-1' is not seconds >= 0"),
        ("nan > A", "time 'nan' is not seconds >= 0"),
        ("0.1 = A", "direction '=' must be '>'"),
        ("0.1 > A B", "column 2: ' ' cannot stand for itself"),
        ("0.1 > \\q", "column 1: '\\\\' cannot stand for itself"),
        ("@timeout 3", "unknown directive @timeout (known: @board, @tolerance"),
        ("@", "unknown directive @ (known:"),  # found by fuzz/fuzz_decoders.py
    ],
)
def test_malformed_lines_name_file_and_line(tmp_path: Path, line: str, message: str) -> None:
    path = tmp_path / "bad.transcript"
    path.write_text(f"{HEADER}\n0.0 > J\n{line}\n")
    with pytest.raises(TranscriptError) as caught:
        read_transcript(path)
    assert str(caught.value).startswith(f"{path}:3: ")
    assert message in str(caught.value)


def test_other_versions_and_unreadable_files() -> None:
    with pytest.raises(TranscriptError, match="v2' is not a version this appmode reads"):
        parse_transcript("# appmode transcript v2\n", "x.transcript")
    with pytest.raises(AppmodeError, match=r"cannot read transcript /no/such\.transcript"):
        read_transcript("/no/such.transcript")


def test_non_utf8_file_is_reported_at_its_line(tmp_path: Path) -> None:
    path = tmp_path / "latin.transcript"
    path.write_bytes(HEADER.encode() + b"\n0.0 > A\n0.0 > \xff\n")
    with pytest.raises(TranscriptError, match=r"latin\.transcript:3: not UTF-8 text \(byte 7 "):
        read_transcript(path)


def test_a_file_that_is_no_transcript_fails_at_once_with_a_short_message(
    tmp_path: Path,
) -> None:
    path = tmp_path / "zeros"
    path.write_bytes(b"\0" * (MAX_LINE + 1))  # like /dev/zero, which never ends
    with pytest.raises(TranscriptError, match=r"zeros:1: a line of over 65,536 bytes"):
        read_transcript(path)
    path.write_text("9" * 5000 + " > A\n")
    with pytest.raises(TranscriptError) as caught:
        read_transcript(path)
    assert len(str(caught.value)) < 150 + len(str(path)) and "(5,000 chars)" in str(caught.value)


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_dev_zero_is_refused_not_read_to_the_end() -> None:
    with pytest.raises(TranscriptError, match="/dev/zero:1: a line of over"):
        read_transcript("/dev/zero")


@given(st.text(max_size=300))
def test_property_reader_never_fails_other_than_clearly(text: str) -> None:
    try:
        transcript = parse_transcript(text, "fuzz.transcript")
    except TranscriptError as exc:
        assert str(exc).startswith("fuzz.transcript:")
    else:
        assert all(e.direction in "<>" and e.time >= 0 for e in transcript.entries)


@given(st.lists(st.tuples(st.sampled_from("<>"), st.binary(min_size=1, max_size=30)), max_size=10))
def test_property_record_then_read_round_trip(chunks: list[tuple[str, bytes]]) -> None:
    out = io.StringIO()
    recorder = Recorder(out)
    for k, (direction, data) in enumerate(chunks):
        recorder(direction, k * 0.01, data)
    recorder.close()
    entries = parse_transcript(out.getvalue()).entries
    for direction in "<>":
        sent = b"".join(d for dr, d in chunks if dr == direction)
        assert b"".join(e.data for e in entries if e.direction == direction) == sent


def _recorded(calls: list[tuple[str, float, bytes]]) -> list[str]:
    out = io.StringIO()
    recorder = Recorder(out)
    for direction, time, data in calls:
        recorder(direction, time, data)
    recorder.close()
    return out.getvalue().splitlines()[1:]


def test_a_recording_stays_in_time_order_when_a_frame_never_ends() -> None:
    """Issue 22.12: `{Q:Z` left open was written, at its own time, after every later
    record. Its bytes are written as far as they go, in their place."""
    calls = [(">", 18.0575, b"{Q:Z")]
    calls += [("<", 18.1 + 0.05 * i, b"{A0:0:0:0}$") for i in range(20)]
    lines = _recorded(calls)
    times = [float(line.split(" ", 1)[0]) for line in lines]
    assert times == sorted(times)
    assert lines[0] == "18.0575 > {Q:Z"


def test_a_unit_that_ends_soon_stays_whole_and_in_its_place() -> None:
    lines = _recorded(
        [(">", 1.0, b"{Q:"), ("<", 1.01, b"{A0:0:0:0}$"), (">", 1.02, b"P}"), ("<", 1.06, b"{B")]
    )
    assert lines == ["1.0000 > {Q:P}", "1.0100 < {A0:0:0:0}$", "1.0600 < {B"]
