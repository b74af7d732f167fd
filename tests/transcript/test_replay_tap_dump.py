"""replay (absolute deadlines), tap (both directions recorded), dump and plot."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import pty
import re
import select
import signal
import subprocess
import sys
import time
import tty
from pathlib import Path

import pytest
import serial

from appmode.protocol.transcript import parse_transcript
from appmode.transcript.reading import read_transcript
from appmode.transcript.replay import EARLY, plan, play
from tests.support.processes import ROOT, board_process, run, wait_for

SESSION = """# appmode transcript v1
# a short session
0.0000 > J
0.1000 < {A0:0:0:0}$
0.2000 > A
0.3000 < {B3:0:0:100}$
0.5000 < {A0:432:0:0}$
0.6000 > Z
0.7000 < {B0:0:0:99}$
"""


def session_file(tmp_path: Path) -> Path:
    path = tmp_path / "session.transcript"
    path.write_text(SESSION)
    return path


def test_play_keeps_absolute_deadlines_on_a_virtual_clock() -> None:
    clock = {"now": 0.0}
    sent: list[tuple[float, bytes]] = []

    def sleep(seconds: float) -> None:
        clock["now"] += seconds + 0.004  # every sleep overshoots by 4 ms

    late = play(
        [(0.01 * k, b"A") for k in range(100)],
        lambda d: sent.append((clock["now"], d)),
        clock=lambda: clock["now"],
        sleep=sleep,
    )
    assert max(late) <= 0.0041, "overshoot never accumulates"
    assert sent[-1][0] == pytest.approx(0.99, abs=0.005)


def test_play_sleeps_to_just_before_each_deadline_then_to_it() -> None:
    clock = {"now": 0.0}
    slept: list[float] = []

    def sleep(seconds: float) -> None:  # exact: wakes when asked
        if seconds < 0:
            raise ValueError("sleep length must be non-negative")  # as time.sleep
        assert len(slept) < 10, f"sleeps without end: {slept}"
        slept.append(seconds)
        clock["now"] += seconds

    late = play(
        [(0.01, b"A"), (0.02, b"B")], lambda d: None, clock=lambda: clock["now"], sleep=sleep
    )
    assert late == [0.0, 0.0], "never early, never late on an exact clock"
    assert slept == pytest.approx([0.01 - EARLY, EARLY, 0.01 - EARLY, EARLY])


def test_plan_speed_and_loops() -> None:
    entries = [(e.time, e.direction, e.data) for e in parse_transcript(SESSION).entries]
    assert [d for _, d in plan(entries, "host")] == [b"J", b"A", b"Z"]
    assert next(d for _, d in plan(entries, "board")) == b"{A0:0:0:0}$"
    times: list[float] = []
    start = time.monotonic()
    play(plan(entries, "host"), lambda d: times.append(time.monotonic() - start), speed=2, loops=2)
    due = [0.0, 0.1, 0.3, 0.3, 0.4, 0.6]  # half the transcript's times, twice over
    assert len(times) == len(due)
    late = [t - d for t, d in zip(times, due, strict=True)]
    assert all(-0.001 <= x < 0.05 for x in late), late  # never early; a loaded machine lags


def test_replay_as_host_drives_a_board_and_ends_with_z(tmp_path: Path) -> None:
    board_log = tmp_path / "board.transcript"

    def took() -> list[tuple[float, str]]:
        lines = board_log.read_text().splitlines()[1:]
        return [(float(t), p) for t, d, p in (line.split(" ", 2) for line in lines) if d == ">"]

    with board_process("--listen", "0", "--quiet", "--record", str(board_log)) as board:
        done = run("replay", str(session_file(tmp_path)), "--to", board.url)
        # the replay's bytes are out when it ends; the board records them as it reads them
        with contextlib.suppress(AssertionError):
            wait_for(lambda: len(took()) >= 4, timeout=5)
    assert done.returncode == 0, done.stderr
    assert "replayed 3 commands" in done.stderr
    sent = took()
    assert [p for _, p in sent] == ["J", "A", "Z", "Z"]
    gaps = [sent[1][0] - sent[0][0], sent[2][0] - sent[1][0]]
    assert gaps == [pytest.approx(0.2, abs=0.03), pytest.approx(0.4, abs=0.03)]


def test_replay_as_board_feeds_an_app_on_a_pty(tmp_path: Path) -> None:
    master, slave = pty.openpty()
    tty.setraw(slave)
    try:
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "appmode",
                "replay",
                str(session_file(tmp_path)),
                "--to",
                os.ttyname(slave),
                "--side",
                "board",
            ],
            cwd=ROOT,
            stderr=subprocess.PIPE,
        )
        received = b""
        end = time.monotonic() + 10
        while proc.poll() is None and time.monotonic() < end:
            if select.select([master], [], [], 0.05)[0]:
                received += os.read(master, 4096)
        while select.select([master], [], [], 0.1)[0]:
            received += os.read(master, 4096)
    finally:
        os.close(master)
        os.close(slave)
    assert received == b"{A0:0:0:0}${B3:0:0:100}${A0:432:0:0}${B0:0:0:99}$"


def test_replay_errors(tmp_path: Path) -> None:
    only_host = tmp_path / "host.transcript"
    only_host.write_text("0.0 > J\n")
    done = run("replay", str(only_host), "--to", "sim://", "--side", "board")
    assert done.returncode == 2 and "has no '<' lines to play as the board" in done.stderr
    done = run("replay", str(only_host), "--to", "sim://", "--speed", "0")
    assert done.returncode == 2 and "--speed: '0' is not a number in [0.001, 1,000]" in done.stderr


def start_tap(board: str, record: Path) -> subprocess.Popen[str]:
    """`appmode tap pty BOARD`: its first line is the pty's."""
    return subprocess.Popen(
        [sys.executable, "-m", "appmode", "tap", "pty", board, "--record", str(record)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_tap_forwards_and_records_both_ways(tmp_path: Path) -> None:
    record = tmp_path / "tap.transcript"
    with board_process("--listen", "0", "--quiet", "--record", str(tmp_path / "b.t")) as board:
        tap = start_tap(board.url, record)
        assert tap.stdout is not None
        path = tap.stdout.readline().split("port: ")[1].strip()
        app = serial.Serial(path, 9600, timeout=0.2)
        app.write(b"{Q:P}JA")
        got = b""
        end = time.monotonic() + 5
        while b"{C" not in got and time.monotonic() < end:
            got += app.read(256)
        app.close()
        tap.send_signal(signal.SIGINT)
        _, err = tap.communicate(timeout=10)
        board_log = board.stop()
    assert b"{C500:10000:20:0:10:10:10:0:0}$" in got
    lines = record.read_text().splitlines()
    sent = [line.split(" ", 2)[2] for line in lines if " > " in line]
    assert sent == ["{Q:P}", "J", "A", "Z"], "the tap stops the car on its way out"
    assert any(" < {C500:" in line for line in lines)
    assert "bytes app->board" in err and "Traceback" not in board_log
    board_sent = [
        line.split(" ", 2)[2]
        for line in (tmp_path / "b.t").read_text().splitlines()
        if " > " in line
    ]
    assert board_sent[-1] == "Z"


def test_tap_says_in_the_transcript_which_side_left(tmp_path: Path) -> None:
    record = tmp_path / "tap.transcript"
    with board_process("--listen", "0", "--quiet") as board:
        tap = start_tap(board.url, record)
        assert tap.stdout is not None
        tap.stdout.readline()
        wait_for(lambda: record.exists() and " < {A" in record.read_text())
        board.stop()  # the car's side goes away
        _, err = tap.communicate(timeout=10)
    assert tap.returncode == 1 and "tap: stopped: board side:" in err
    transcript = read_transcript(record)
    assert transcript.title == f"tap: pty <-> {board.url}"
    assert re.search(r"^# the board side left at \d+\.\d{3} s: ", record.read_text(), re.M)


def test_dump_text_json_csv(tmp_path: Path) -> None:
    path = session_file(tmp_path)
    text = run("dump", str(path)).stdout
    assert "0.500 < {A0:432:0:0}$" in text and "velocity x=0 y=432 z=0" in text
    objects = [json.loads(line) for line in run("dump", str(path), "--json").stdout.splitlines()]
    assert objects[0] == {
        "t": 0.0,
        "dir": ">",
        "kind": "page",
        "letter": "J",
        "page": "direction",
        "mode": "joystick",
        "raw": "J",
    }
    rows = list(csv.DictReader(io.StringIO(run("dump", str(path), "--csv").stdout)))
    assert rows[4]["kind"] == "velocity" and rows[4]["y"] == "432"
    assert len(rows) == 7


def test_plot_writes_a_png(tmp_path: Path) -> None:
    record = tmp_path / "drive.transcript"
    run(
        "drive",
        "--record",
        str(record),
        stdin=b"drive A\nwait 0.5\npage button\ndrive C\nwait 0.5\nstop\nwait 0.3\n",
    )
    image = tmp_path / "out.png"
    done = run("plot", str(record), "-o", str(image))
    assert done.returncode == 0, done.stderr
    assert image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and image.stat().st_size > 20_000


def test_plot_and_dump_read_a_minibalance_transcript_by_its_profile(tmp_path: Path) -> None:
    record = tmp_path / "mb.transcript"
    done = run("send", "sim://?profile=minibalance", "--record", str(record), "wait:2.0", "J", "A")
    assert done.returncode == 0, done.stderr
    assert "@board profile=minibalance" in record.read_text()
    dumped = run("dump", str(record), "--json")
    rows = [json.loads(line) for line in dumped.stdout.splitlines()]
    assert any(r.get("kind") == "velocity" and "abs_y" in r for r in rows)
    image = tmp_path / "mb.png"
    assert run("plot", str(record), "-o", str(image)).returncode == 0
    assert image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_without_records_is_a_clear_error(tmp_path: Path) -> None:
    path = tmp_path / "empty.transcript"
    path.write_text("0.0 > J\n")
    done = run("plot", str(path), "-o", str(tmp_path / "x.png"))
    assert done.returncode == 2
    assert "has no A or B records, no encoder reports (UART2, §12) and no chassis" in done.stderr
    assert not (tmp_path / "x.png").exists()


def test_read_transcript_of_the_suite_is_consistent() -> None:
    for path in (ROOT / "transcripts" / "suite").glob("*.transcript"):
        assert read_transcript(path).entries


def test_plot_without_matplotlib_names_the_package_to_install(tmp_path: Path) -> None:
    path = tmp_path / "t.transcript"
    path.write_text("# appmode transcript v1\n0.0 < {A0:0:0:0}$\n")
    code = (
        "import sys; sys.modules['matplotlib'] = None\n"
        "from appmode.cli.main import main\n"
        f"sys.exit(main(['plot', {str(path)!r}, '-o', {str(tmp_path / 'x.png')!r}]))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 2
    assert "pip install matplotlib" in done.stderr and "appmode[plot]" not in done.stderr


def test_dump_shows_wildcard_lines_as_expectations_and_csv_every_field(tmp_path: Path) -> None:
    path = tmp_path / "w.transcript"
    path.write_text(
        "# appmode transcript v1\n0.0 > {Q:P}\n0.1 < {C*:*:*:*:*:*:*:*:*}$\n"
        "0.2 < {A0:*:0:0}$\n0.3 < {A1:2:3:4}$\n0.4 > \\x01\n"
    )
    text = run("dump", str(path)).stdout
    assert "expectation x=0 y=* z=0 extra=0" in text and "error" not in text
    objects = [json.loads(line) for line in run("dump", str(path), "--json").stdout.splitlines()]
    assert objects[2] == {
        "t": 0.2,
        "dir": "<",
        "kind": "expectation",
        "letter": "A",
        "x": 0,
        "y": "*",
        "z": 0,
        "extra": 0,
        "raw": "{A0:*:0:0}$",
    }
    rows = list(csv.DictReader(io.StringIO(run("dump", str(path), "--csv").stdout)))
    for row, obj in zip(rows, objects, strict=True):  # every field of the JSON is a column
        assert {k: str(v) for k, v in obj.items()} == {k: v for k, v in row.items() if v}
    assert rows[3]["extra"] == "4"


def test_gap_and_skip_retime_the_pauses_as_python_can_player_does() -> None:
    from appmode.transcript.replay import retime

    items = [(1.0, b"J"), (1.05, b"A"), (9.0, b"B"), (9.5, b"Z")]
    assert [t for t, _ in retime(items)] == [1.0, 1.05, 9.0, 9.5]
    assert [t for t, _ in retime(items, gap=0.2)] == pytest.approx([1.0, 1.2, 9.15, 9.65])
    assert [t for t, _ in retime(items, skip=1.0)] == pytest.approx([1.0, 1.05, 2.05, 2.55])
    assert [t for t, _ in retime(items, gap=0.2, skip=1.0)] == pytest.approx([1.0, 1.2, 2.2, 2.7])


def test_replay_verbose_prints_each_line_as_it_is_played(tmp_path: Path) -> None:
    path = tmp_path / "r.transcript"
    path.write_text("# appmode transcript v1\n0.0 > J\n0.1 > A\n30.0 > Z\n")
    done = run("replay", str(path), "--to", "sim://", "-v", "--skip", "0.3", timeout=20)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert [line.split()[1:3] for line in lines] == [[">", "J"], [">", "A"], [">", "Z"]]
    assert "move A (direction 1)" in lines[1]
    assert 0.3 <= float(lines[2].split()[0]) < 1.0  # 30 s skipped down to 0.3


def test_replay_to_a_new_pty_feeds_the_app_that_opens_it(tmp_path: Path) -> None:
    path = tmp_path / "board.transcript"
    path.write_text("# appmode transcript v1\n0.0 < {A0:1:0:0}$\n0.2 < {B0:0:0:99}$\n")
    proc = subprocess.Popen(
        [sys.executable, "-m", "appmode", "replay", str(path), "--to", "pty", "--side", "board"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=ROOT,
    )
    try:
        assert proc.stdout is not None
        device = proc.stdout.readline().decode().split("port: ")[1].strip()
        fd = os.open(device, os.O_RDWR | os.O_NOCTTY)
        try:
            tty.setraw(fd)
            time.sleep(0.3)
            assert not select.select([fd], [], [], 0)[0], "nothing before the app speaks"
            os.write(fd, b"J")  # the app asks: the replay starts
            got = b""
            end = time.monotonic() + 5
            while b"{B0:0:0:99}$" not in got and time.monotonic() < end:
                if select.select([fd], [], [], 0.1)[0]:
                    got += os.read(fd, 256)
        finally:
            os.close(fd)
        assert proc.wait(10) == 0
    finally:
        proc.kill()
    assert got == b"{A0:1:0:0}${B0:0:0:99}$"


def test_command_labels_close_in_time_share_one_label() -> None:
    from appmode.transcript.plot import command_labels

    commands = [(0.0, "J"), (0.004, "{Q:P}"), (0.5, "B"), (0.502, "C"), (0.503, "D"), (1.0, "Z")]
    assert command_labels(commands, 0.01) == [(0.0, "J {Q:P}"), (0.5, "B C D"), (1.0, "Z")]
    many = [(i * 0.001, "{0:12345}") for i in range(5)]
    assert command_labels(many, 0.01) == [(0.0, "{0:12345} {0:12…")]


def test_plot_draws_a_uart2_transcript_s_encoder_reports(tmp_path: Path) -> None:
    """Issue 49.14: a UART2 transcript 'has no A or B records to plot'."""
    out = tmp_path / "u.png"
    done = run(
        "plot", str(ROOT / "transcripts" / "examples" / "uart2_session.transcript"), "-o", str(out)
    )
    assert done.returncode == 0, done.stderr
    assert out.read_bytes().startswith(b"\x89PNG")


def test_plot_s_title_is_whole_and_its_labels_stand_apart() -> None:
    from appmode.transcript.plot import _title
    from appmode.transcript.reading import read_transcript

    path = ROOT / "transcripts" / "suite" / "s4_letters_omni.transcript"
    title = _title(str(path), read_transcript(path).title)
    assert all(len(line) <= 110 for line in title.splitlines())
    assert not title.endswith(","), "a title cut at a comma reads as clipped"
