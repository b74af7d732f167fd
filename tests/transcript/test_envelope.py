"""Issue 64.9: `plot` held every point (a 20 MB transcript peaked at 719 MB). Each series
is now reduced as it streams to its extremes per time bin, in bounded memory."""

from __future__ import annotations

import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

from appmode.transcript.envelope import BINS, Envelope, Marks, TimeBins
from tests.support.processes import appmode_cmd


def test_a_short_series_is_kept_as_it_is() -> None:
    envelope = Envelope()
    points = [(i * 0.06, float(i % 7)) for i in range(500)]
    for t, value in points:
        envelope.add(t, value)
    times, values = envelope.points()
    assert list(zip(times, values, strict=True)) == points


def test_a_long_series_keeps_its_extremes_in_bounded_bins() -> None:
    random.seed(7)
    envelope = Envelope()
    points = [(i * 0.06, random.uniform(-500, 500)) for i in range(200_000)]
    points[123_456] = (points[123_456][0], 9_999.0)
    points[77] = (points[77][0], -9_999.0)
    for t, value in points:
        envelope.add(t, value)
    times, values = envelope.points()
    assert len(times) <= 4 * BINS
    assert max(values) == 9_999.0 and min(values) == -9_999.0
    assert times[values.index(9_999.0)] == points[123_456][0], "at its own time"
    assert times == sorted(times) and times[0] == 0.0
    assert times[-1] == points[-1][0], "where it ends"


def test_bins_merge_pairs_as_time_outgrows_them() -> None:
    bins: TimeBins[int] = TimeBins(lambda a, b: a + b, size=8)
    for t in range(1000):
        bins.put(float(t), 1)
    kept = bins.kept()
    assert len(kept) <= 8 and sum(kept) == 1000, "every value counted once"
    odd: TimeBins[int] = TimeBins(lambda a, b: a + b, size=7)
    for t in range(1000):
        odd.put(float(t), 1)
    assert len(odd.kept()) <= 7 and sum(odd.kept()) == 1000, "an odd last bin is kept too"
    marks = Marks(size=4)
    for t in range(100):
        marks.add(t * 1.0, f"c{t}")
    assert marks.kept()[0] == (0.0, "c0") and len(marks.kept()) <= 4


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="os.wait4 gives the child's peak memory")
def test_plot_s_memory_does_not_grow_with_the_file(tmp_path: Path) -> None:
    peaks = []
    for lines in (30_000, 90_000):  # both past what the picture holds
        path = tmp_path / f"drive{lines}.transcript"
        random.seed(lines)
        with path.open("w") as out:
            out.write("# appmode transcript v1\n# a long drive\n")
            for i in range(lines):
                out.write(f"{i * 0.06:.4f} < {{A{random.randint(0, 255)}:0:99:0}}$\n")
                if i % 50 == 0:
                    out.write(f"{i * 0.06 + 0.01:.4f} > A\n")
        proc = subprocess.Popen(
            appmode_cmd("plot", str(path), "-o", str(tmp_path / f"{lines}.png")),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        _, status, usage = os.wait4(proc.pid, 0)
        assert os.waitstatus_to_exitcode(status) == 0
        peaks.append(usage.ru_maxrss / 1024)  # kB on Linux
    assert abs(peaks[1] - peaks[0]) < 15, f"peak RSS {peaks[0]:.0f} MB, then {peaks[1]:.0f} MB"
    assert peaks[1] < 250
