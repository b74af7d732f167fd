"""MCAP recordings (issue 68.2, 68.3, 68.5): `.mcap` chooses the format of every
recording; dump, replay, conform and plot read it as a transcript; `appmode convert` is
lossless both ways over the shipped suite; a corrupt, cut or foreign file is one line
and a non-zero exit."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

pytest.importorskip("mcap", reason="the foxglove extra (mcap) is not installed")

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from appmode.protocol.transcript import TranscriptError
from appmode.transcript.convert import run_convert
from appmode.transcript.dump import run_dump
from appmode.transcript.reading import iter_lines, read_transcript
from appmode.transcript.runner import SUITE
from tests.support.processes import run

SUITE_FILES = sorted(SUITE.rglob("*.transcript"))
EXAMPLES = sorted((SUITE.parent / "examples").rglob("*.transcript"))


def dumped(path: Path) -> str:
    out = io.StringIO()
    run_dump(str(path), "json", out)
    return out.getvalue()


def lines_of(path: Path) -> list[object]:
    return list(iter_lines(path, lambda text: None))


@pytest.mark.parametrize("source", SUITE_FILES + EXAMPLES, ids=lambda p: p.name)
def test_convert_is_lossless_both_ways(source: Path, tmp_path: Path) -> None:
    mcap, back, again = tmp_path / "a.mcap", tmp_path / "b.transcript", tmp_path / "c.mcap"
    run_convert(str(source), str(mcap), None, False)
    run_convert(str(mcap), str(back), None, False)
    run_convert(str(back), str(again), None, False)
    assert dumped(mcap) == dumped(source) == dumped(back)
    # every line comes back as it was, at its line number: comments and directives too
    assert lines_of(mcap) == lines_of(source) == lines_of(back)
    assert again.read_bytes() == mcap.read_bytes()


def test_a_recording_named_mcap_is_mcap_with_decoded_channels(tmp_path: Path) -> None:
    path = tmp_path / "drive.mcap"
    done = run("drive", "sim://", "--record", str(path), stdin=b"drive A\nwait 0.6\nstop\n")
    assert done.returncode == 0, done.stderr
    with path.open("rb") as handle:
        reader = make_reader(handle)
        summary = reader.get_summary()
        assert summary is not None and reader.get_header().profile == "appmode"
        topics = {c.topic for c in summary.channels.values()}
        assert {"/raw/app/sent", "/raw/app/received", "/app/A", "/pose", "/tf"} <= topics
        schema = next(json.loads(s.data) for s in summary.schemas.values() if s.name == "appmode.A")
        assert {"x", "y", "z"} <= set(schema["properties"])
        sent = [
            bytes.fromhex(json.loads(m.data)["hex"])
            for _, c, m in reader.iter_messages(topics=["/raw/app/sent"])
        ]
        poses = [json.loads(m.data) for _, _, m in reader.iter_messages(topics=["/pose"])]
    assert b"A" in sent and sent[-1] == b"Z"
    assert poses[-1]["frame_id"] == "odom" and poses[-1]["pose"]["position"]["x"] > 0.1
    # the raw channels are the transcript: dump reads them as it reads text
    text = read_transcript(path)
    assert [e.data for e in text.entries if e.direction == ">"] == sent


def test_record_and_replay_read_mcap(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    done = run("record", "sim://", str(path), "--count", "5")
    assert done.returncode == 0, done.stderr
    assert len(read_transcript(path).entries) >= 5
    shown = run("dump", str(path))
    assert shown.returncode == 0 and "velocity" in shown.stdout


def test_conform_runs_an_mcap_file(tmp_path: Path) -> None:
    source = SUITE / "s2_1_unrecognised_bytes_stop.transcript"
    mcap = tmp_path / f"{source.stem}.mcap"
    run_convert(str(source), str(mcap), None, False)
    done = run("conform", str(mcap))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 passed" in done.stdout + done.stderr


@pytest.fixture
def recording(tmp_path: Path) -> Path:
    path = tmp_path / "whole.mcap"
    run_convert(str(SUITE / "s5_set_each_param.transcript"), str(path), None, False)
    return path


def one_line_error(*args: str) -> str:
    done = run(*args)
    assert done.returncode != 0
    assert "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    return line


def test_a_corrupt_mcap_is_one_line(recording: Path, tmp_path: Path) -> None:
    data = bytearray(recording.read_bytes())
    bad = tmp_path / "bad.mcap"
    for offset in (9, 40, len(data) // 2, len(data) - 30):
        flipped = bytearray(data)
        flipped[offset] ^= 0xFF
        bad.write_bytes(bytes(flipped))
        line = one_line_error("dump", str(bad))
        assert line.startswith(f"appmode: error: {bad}"), line


def test_a_cut_mcap_says_so_and_partial_keeps_what_it_holds(tmp_path: Path) -> None:
    recording = tmp_path / "rec.mcap"  # 3 s of records: a chunk a second
    done = run("record", "sim://", str(recording), "--count", "60")
    assert done.returncode == 0, done.stderr
    cut = tmp_path / "cut.mcap"
    whole = recording.read_bytes()
    cut.write_bytes(whole[: len(whole) // 3])  # within the chunks: the summary is after
    line = one_line_error("dump", str(cut))
    assert "cut short" in line and "--partial" in line
    out = tmp_path / "kept.transcript"
    done = run("convert", "--partial", str(cut), str(out))
    assert done.returncode == 0, done.stderr
    assert "cut short" in done.stderr
    kept = read_transcript(out).entries
    assert 0 < len(kept) < len(read_transcript(recording).entries)


def test_a_foreign_mcap_is_named_as_such(tmp_path: Path) -> None:
    path = tmp_path / "ros.mcap"
    with path.open("wb") as handle:
        writer = Writer(handle)
        writer.start(profile="ros2", library="test")
        writer.finish()
    line = one_line_error("dump", str(path))
    assert "profile 'ros2'" in line and "not an appmode recording" in line


def test_chunks_from_other_writers_are_read_and_bounded(tmp_path: Path) -> None:
    """A file another MCAP writer made from ours (chunked, compressed) reads the same; a
    record that claims more than the reader's bound is refused, not allocated."""
    source = SUITE_FILES[0]
    ours = tmp_path / "ours.mcap"
    run_convert(str(source), str(ours), None, False)
    chunked = tmp_path / "chunked.mcap"
    with ours.open("rb") as handle, chunked.open("wb") as out:
        reader = make_reader(handle)
        writer = Writer(out, compression=CompressionType.ZSTD, chunk_size=512)
        writer.start(profile="appmode", library="rewritten")
        ids: dict[int, int] = {}
        for _, channel, message in reader.iter_messages(log_time_order=False):
            if channel.id not in ids:
                ids[channel.id] = writer.register_channel(
                    channel.topic, channel.message_encoding, 0, channel.metadata
                )
            writer.add_message(
                ids[channel.id],
                message.log_time,
                message.data,
                message.publish_time,
                message.sequence,
            )
        writer.finish()
    assert lines_of(chunked) == lines_of(source)
    huge = tmp_path / "huge.mcap"
    huge.write_bytes(b"\x89MCAP0\r\n" + b"\x01" + (2**40).to_bytes(8, "little") + b"x" * 64)
    with pytest.raises(TranscriptError, match="not a readable MCAP file"):
        list(iter_lines(huge, lambda text: None))


def test_convert_refuses_to_write_over_its_input(recording: Path) -> None:
    before = recording.read_bytes()
    line = one_line_error("convert", str(recording), str(recording))
    assert "is the file being read" in line
    assert recording.read_bytes() == before


def test_a_recording_is_indexed_wall_clocked_and_every_channel_has_a_schema(
    tmp_path: Path,
) -> None:
    """Issue 78.3: what an indexed reader (a seeking one, from the summary) reads is every
    message; log times are the wall clock; /log and /session/in_force are there."""
    import time

    from mcap.reader import SeekingReader
    from mcap.stream_reader import StreamReader

    path = tmp_path / "drive.mcap"
    before = time.time()
    done = run("drive", "sim://", "--record", str(path), stdin=b"drive A\nwait 0.6\nstop\n")
    assert done.returncode == 0, done.stderr
    with path.open("rb") as handle:
        streamed = sum(1 for r in StreamReader(handle).records if type(r).__name__ == "Message")
    with path.open("rb") as handle:
        reader = SeekingReader(handle)
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes  # chunked and indexed
        assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
        indexed = list(reader.iter_messages())
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    assert len(indexed) == streamed > 50
    assert all(c.schema_id != 0 for c in summary.channels.values())  # every one decodes
    assert {c.message_encoding for c in summary.channels.values()} == {"json"}
    times = [m.log_time / 1e9 for _, _, m in indexed]
    assert before - 1 <= min(times) and max(times) <= time.time() + 1
    start = int(metadata["appmode"]["start_ns"]) / 1e9
    assert before - 1 <= start <= min(times)
    topics = {c.topic for _, c, _ in indexed}
    assert {"/log", "/session/in_force"} <= topics
    in_force = [json.loads(m.data) for _, c, m in indexed if c.topic == "/session/in_force"]
    assert in_force[0]["command"] == "A" and not in_force[-1]["moving"]
    # its transcript keeps its own clock, and the date in a directive; back, the same times
    back, again = tmp_path / "back.transcript", tmp_path / "again.mcap"
    run_convert(str(path), str(back), None, False)
    text = back.read_text()
    assert "\n@recorded 20" in text and "\n0.0" in text
    run_convert(str(back), str(again), None, False)
    with again.open("rb") as handle:
        times_again = [m.log_time / 1e9 for _, _, m in SeekingReader(handle).iter_messages()]
    raw = [t for t, (_, c, _) in zip(times, indexed, strict=True) if c.topic.startswith("/raw/")]
    assert set(raw) <= set(times_again)


@pytest.mark.parametrize("data", [b"", b"\x89MCAP", b"\x89MCAP0\r\n\x01"], ids=len)
def test_an_empty_or_headless_mcap_is_one_line_and_exit_2(data: bytes, tmp_path: Path) -> None:
    path = tmp_path / "empty.mcap"
    path.write_bytes(data)
    done = run("dump", str(path))
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert (
        done.stderr.strip() == f"appmode: error: {path}: an empty or broken MCAP file (no "
        "whole header): nothing to read"
    )


def _one_channel(path: Path, encoding: str, data: bytes) -> None:
    with path.open("wb") as handle:
        writer = Writer(handle, compression=CompressionType.NONE)
        writer.start(profile="appmode", library="another writer")
        channel = writer.register_channel("/raw/app/sent", encoding, 0)
        writer.add_message(channel, log_time=10**9, data=data, publish_time=10**9, sequence=2)
        writer.finish()


def test_the_reader_honours_each_channels_encoding(tmp_path: Path) -> None:
    path = tmp_path / "live.mcap"
    _one_channel(path, "json", b'{"text": "A", "hex": "41", "length": 1}')
    assert [(e.time, e.data) for e in read_transcript(path).entries] == [(1.0, b"A")]
    _one_channel(path, "cbor", b"\xa1")
    line = one_line_error("dump", str(path))
    assert "/raw/app/sent is encoded as 'cbor', not as appmode writes it (json)" in line
    _one_channel(path, "json", b"A")
    assert "not appmode's JSON" in one_line_error("dump", str(path))


def test_no_corrupt_byte_makes_an_unclear_message(recording: Path, tmp_path: Path) -> None:
    """Issue 78.3: a byte flipped anywhere is one line that names the file and says what
    is wrong, never a bare "()" or a struct module's words, and never a traceback."""
    data = recording.read_bytes()
    bad = tmp_path / "bad.mcap"
    said: set[str] = set()
    for offset in range(0, len(data), max(1, len(data) // 150)):
        flipped = bytearray(data)
        flipped[offset] ^= 0x5A
        bad.write_bytes(bytes(flipped))
        try:
            list(iter_lines(bad, lambda text: None))
        except TranscriptError as exc:
            text = str(exc)
            assert text.startswith(f"{bad}: ") and "\n" not in text, text
            assert "()" not in text and "unpack requires" not in text, text
            said.add(text.split(": ", 1)[1][:40])
    assert said  # the CRCs catch flips: some of them are refused


def test_a_bad_recorded_directive_is_one_line_at_its_place(tmp_path: Path) -> None:
    source = tmp_path / "bad.transcript"
    source.write_text("# appmode transcript v1\n@recorded yesterday\n0.1 > A\n")
    line = one_line_error("convert", str(source), str(tmp_path / "bad.mcap"))
    assert line == (
        f"appmode: error: {source}:2: @recorded takes a UTC time such as "
        "2026-11-29T08:00:00.000000Z"
    )
    assert not (tmp_path / "bad.mcap").exists()
