"""A recording cut short — by a full disk, a killed recorder — stays readable: its last
line, with no end, is left out with a warning (issue 22.9); a recording that could not
write even its header leaves no empty file; dump reads in constant memory (22.8)."""

from __future__ import annotations

import io
import resource
import signal
import time
import tracemalloc
from pathlib import Path

import pytest

from appmode.errors import AppmodeError
from appmode.ports.recording import open_recorder
from appmode.protocol.transcript import TranscriptError, parse_transcript
from appmode.transcript.dump import run_dump
from appmode.transcript.reading import read_transcript
from appmode.writer import BoundedWriter
from tests.support.processes import run

WHOLE = "# appmode transcript v1\n0.000 > J\n0.050 > A\n0.400 < {A0:1..500:0:0}$\n1.000 > Z\n"


@pytest.fixture
def cut(tmp_path: Path) -> Path:
    path = tmp_path / "cut.transcript"
    path.write_text(WHOLE + "1.0500 < {A0:12}\\x2")  # the disk filled in an escape
    return path


def test_the_last_line_cut_short_is_left_out_with_a_warning(cut: Path) -> None:
    transcript = read_transcript(cut)
    assert [e.text for e in transcript.entries] == ["J", "A", "{A0:1..500:0:0}$", "Z"]
    (warning,) = transcript.warnings
    assert warning.startswith(f"{cut}:6: ") and "cut short, left out" in warning
    assert parse_transcript(WHOLE + "1.0 < x y").warnings  # the same for text


def test_a_bad_line_that_has_its_end_is_still_an_error(tmp_path: Path) -> None:
    path = tmp_path / "bad.transcript"
    path.write_text(WHOLE + "1.0500 ? {A0:12}$\n")
    with pytest.raises(TranscriptError, match=r"bad\.transcript:6: direction"):
        read_transcript(path)


@pytest.mark.parametrize(
    "args",
    [("dump", "{}"), ("conform", "{}"), ("replay", "{}", "--to", "sim://?pace=0")],
    ids=["dump", "conform", "replay"],
)
def test_commands_read_a_recording_cut_short(cut: Path, args: tuple[str, ...]) -> None:
    done = run(*(a.replace("{}", str(cut)) for a in args))
    assert done.returncode == 0, done.stderr
    assert "WARNING: " in done.stderr and "cut short, left out" in done.stderr
    assert "Traceback" not in done.stderr


def test_a_recording_on_a_disk_already_full_leaves_no_empty_file(tmp_path: Path) -> None:
    record = tmp_path / "full.transcript"

    def no_room() -> None:  # every write past 0 bytes fails (EFBIG), as on a full disk
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))

    done = run("record", "sim://", str(record), "--count", "3", limits=no_room)
    assert done.returncode == 2
    assert "cannot write transcript" in done.stderr
    assert not record.exists()


def test_a_recording_s_writer_scheduled_late_is_no_full_disk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A writer's thread that runs only 0.3 s after it was started (a busy machine) still
    writes the recording's first line: its file was refused as full when the thread was
    not scheduled within 0.1 s (a suite beside a second one). A full one still fails."""
    run_at_once = BoundedWriter._run

    def late(writer: BoundedWriter) -> None:
        time.sleep(0.3)
        run_at_once(writer)

    monkeypatch.setattr(BoundedWriter, "_run", late)
    path = tmp_path / "late.transcript"
    recorder = open_recorder(path)
    recorder.close()
    assert path.read_text().startswith("# appmode transcript v1\n")
    with pytest.raises(AppmodeError, match="No space left on device"):
        open_recorder("/dev/full")


def _dump_peak(path: Path, lines: int) -> int:
    """The most memory `dump --csv` held for a transcript of `lines` A records."""
    with path.open("w") as out:
        out.write("# appmode transcript v1\n")
        for i in range(lines):
            out.write(f"{i * 0.05:.4f} < {{A0:{i % 500}:0:0}}$\n")
    tracemalloc.start()
    try:
        assert run_dump(str(path), "csv", _Null()) == 0
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.slow  # 30,000 records under tracemalloc: 8–12 s
def test_dump_streams_in_constant_memory(tmp_path: Path) -> None:
    """A dump holds no record it has written: for 30,000 records (a file of 750 kB) it
    holds less than the file's size, and under 1 MB (it held 290 kB here)."""
    path = tmp_path / "long.transcript"
    peak = _dump_peak(path, 30_000)
    size = path.stat().st_size
    assert peak < min(size, 1_000_000), f"dump held {peak:,} bytes for a {size:,}-byte file"


class _Null(io.StringIO):
    def write(self, text: str) -> int:
        return len(text)
