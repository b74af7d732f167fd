"""Live to Foxglove (issue 68.1, 68.5): `--foxglove` serves what a session, a board, a
monitor or a replay carries over the official SDK, to a client written from the
WebSocket protocol's description; a viewer that never reads does not hold up the stop;
one that leaves mid-message does not stop the server for the others."""

from __future__ import annotations

import base64
import os
import re
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path
from types import FrameType
from typing import Any

import pytest

pytest.importorskip("foxglove", reason="the foxglove extra is not installed")
pytest.importorskip("websockets", reason="the test extra (websockets) is not installed")

from appmode.transcript.reading import read_transcript
from tests.support.foxglove_client import Seen, serving, watch_sync
from tests.support.processes import ROOT, appmode_cmd, board_process, timed_sent

SCRIPT = "wait 0.6\ndrive A\nwait 1\nstop\nwait 0.3\n"


def test_drive_serves_the_session_with_schemas_the_command_in_force_and_the_pose() -> None:
    with serving("drive", "sim://", stdin=SCRIPT) as (proc, url):
        assert url.startswith("ws://127.0.0.1:")  # loopback unless asked
        seen = watch_sync(url, 6)
        assert proc.wait(10) == 0
    assert seen.info["name"] == "appmode"
    a = seen.channels["/app/A"]
    assert a["encoding"] == "json" and a["schemaEncoding"] == "jsonschema"
    assert {"x", "y", "z"} <= set(__import__("json").loads(a["schema"])["properties"])
    assert seen.channels["/pose"]["schemaName"] == "foxglove.PoseInFrame"
    in_force = seen.json_on("/session/in_force")
    assert [m["command"] for m in in_force][:1] == ["A"] and in_force[-1]["command"] == "Z"
    assert not in_force[-1]["moving"]
    poses = seen.json_on("/pose")
    assert poses[-1]["pose"]["position"]["x"] > 0.2  # forward, dead-reckoned
    sent = [m["text"] for m in seen.json_on("/raw/app/sent")]
    assert sent[-1] == "Z"
    assert any(b"move A" in data for topic, _, data in seen.messages if topic == "/log")


def test_monitor_and_replay_serve_their_records() -> None:
    with serving("monitor", "sim://", "--duration", "2") as (proc, url):
        seen = watch_sync(url, 4)
        assert proc.wait(10) == 0
    assert len(seen.json_on("/app/A")) >= 5 and len(seen.json_on("/app/B")) >= 5
    transcript = ROOT / "transcripts" / "suite" / "s5_save.transcript"
    with serving("replay", str(transcript)) as (proc, url):
        started = time.monotonic()
        seen = watch_sync(url, 6)
        took = time.monotonic() - started
        assert proc.wait(10) == 0
    sent = [m["text"] for m in seen.json_on("/raw/app/sent")]
    played = [e.text for e in read_transcript(transcript).entries if e.direction == ">"]
    assert "".join(sent) == "".join(played)  # every unit from the first: it waited
    assert took >= 0.5  # played at the transcript's pace (it lasts over half a second)


def test_the_board_serves_its_own_view(tmp_path: Path) -> None:
    with serving("board", "--listen", "0") as (board, url):
        assert board.stdout is not None
        port = board.stdout.readline().split()[-1]
        seen: list[Seen] = []
        watcher = threading.Thread(target=lambda: seen.append(watch_sync(url, 4)))
        watcher.start()
        time.sleep(0.3)
        done = subprocess.run(
            appmode_cmd("drive", port), input=SCRIPT, capture_output=True, text=True, cwd=ROOT
        )
        watcher.join()
    assert done.returncode == 0, done.stderr
    commands = [m["command"] for m in seen[0].json_on("/session/in_force")]
    assert "A" in commands and commands[-1] == "Z"


def stalled_viewer(url: str) -> socket.socket:
    """A viewer that opens the WebSocket, subscribes to every channel, and never reads
    again (its receive buffer as small as the system allows)."""
    host, port = url.removeprefix("ws://").rsplit(":", 1)
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
    sock.connect((host, int(port)))
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall(
        (
            f"GET / HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\n"
            f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
            "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.sdk.v1\r\n\r\n"
        ).encode()
    )
    got = b""
    while b"advertise" not in got:
        got += sock.recv(65536)
    ids = sorted({int(i) for i in re.findall(rb'"id":(\d+),"topic"', got)})
    subscribe = (
        '{"op":"subscribe","subscriptions":['
        + ",".join(f'{{"id":{n},"channelId":{c}}}' for n, c in enumerate(ids, 1))
        + "]}"
    ).encode()
    sock.sendall(_client_frame(subscribe))
    return sock


def _client_frame(payload: bytes, opcode: int = 0x1) -> bytes:
    """A masked client frame (RFC 6455 §5.2)."""
    mask = os.urandom(4)
    head = bytes([0x80 | opcode])
    size = len(payload)
    head += bytes([0x80 | size]) if size < 126 else bytes([0x80 | 126]) + size.to_bytes(2, "big")
    return head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload))


@pytest.mark.timing
def test_a_viewer_that_never_reads_does_not_hold_up_the_stop(tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    with (
        board_process("--listen", "0", "--quiet", "--record", str(record), "--no-pace") as board,
        serving("drive", board.url, stdin="wait 0.8\ndrive A\nwait 2\nstop\n") as (proc, url),
    ):
        viewers = [stalled_viewer(url) for _ in range(3)]
        try:
            assert proc.wait(20) == 0
        finally:
            for viewer in viewers:
                viewer.close()
    sent = timed_sent(record)
    a = next(t for t, p in sent if p == "A")
    z = next(t for t, p in sent if p == "Z" and t > a)
    assert z - a == pytest.approx(2.0, abs=0.35), sent  # the stop on time, on the board


def test_a_viewer_leaving_mid_message_leaves_the_server_serving() -> None:
    with serving("monitor", "sim://", "--duration", "4") as (proc, url):
        sock = stalled_viewer(url)
        sock.sendall(_client_frame(b'{"op":"unsubscribe","subscriptionIds":[1]}')[:9])
        sock.close()  # half a frame, then gone
        seen = watch_sync(url, 1.5)
        assert proc.wait(10) == 0
    assert len(seen.json_on("/app/A")) >= 3


def test_another_address_is_warned_about() -> None:
    proc = subprocess.Popen(
        appmode_cmd("monitor", "sim://", "--duration", "0.5", "--foxglove", "0.0.0.0:0"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    _, err = proc.communicate(timeout=20)
    assert proc.returncode == 0, err
    assert "WARNING: the live view is served on 0.0.0.0" in err


def test_a_port_in_use_is_one_line() -> None:
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        done = subprocess.run(
            appmode_cmd("monitor", "sim://", "--duration", "0.5", "--foxglove", str(port)),
            capture_output=True,
            text=True,
            cwd=ROOT,
            timeout=20,
        )
    assert done.returncode != 0 and "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"appmode: error: --foxglove 127.0.0.1:{port}: cannot serve there")


def test_replay_needs_somewhere_to_play() -> None:
    transcript = ROOT / "transcripts" / "suite" / "s5_save.transcript"
    done = subprocess.run(
        [sys.executable, "-m", "appmode", "replay", str(transcript)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert done.returncode != 0 and "--to URL" in done.stderr


def test_a_board_whose_records_are_magnitudes_shows_the_pose_its_frames_sign() -> None:
    """Issue 78.4: minibalance's A record carries |0.7·x| and |0.7·y|; the control port's
    frame in force signs them, and the yaw gives the turn: the board's view has a pose."""
    with serving("board", "--profile", "minibalance") as (board, url):
        assert board.stdout is not None
        ports = dict(board.stdout.readline().strip().split(": ", 1) for _ in range(2))
        seen: list[Seen] = []
        watcher = threading.Thread(target=lambda: seen.append(watch_sync(url, 5)))
        watcher.start()
        time.sleep(0.5)
        script = "wait 0.5\ntwist 0.2 0 0\nwait 1.5\nstop\nwait 0.3\n"
        done = subprocess.run(
            appmode_cmd("drive", ports["uart2"], "--uart2", "--profile", "minibalance"),
            input=script,
            capture_output=True,
            text=True,
            cwd=ROOT,
        )
        watcher.join()
    assert done.returncode == 0, done.stderr
    poses = seen[0].json_on("/pose")
    assert len(poses) > 10
    assert poses[-1]["pose"]["position"]["x"] > 0.15  # forward, from magnitudes signed


def _feed_interrupted_at(step: int) -> tuple[bool, int]:
    """Feed a live view a record with a KeyboardInterrupt raised at its `step`th traced
    step, then close it: whether the close ended within 5 s, and how many steps the
    feed took."""
    from appmode.viewers.live import LiveView

    view = LiveView("127.0.0.1", 0)
    steps = 0

    def tracer(frame: FrameType, event: str, arg: object) -> Any:
        nonlocal steps
        steps += 1
        if steps == step:
            raise KeyboardInterrupt
        return tracer

    sys.settrace(tracer)
    try:
        view("in", 0.0, b"{A1:2:3:4}$")
    except KeyboardInterrupt:
        pass
    finally:
        sys.settrace(None)
    closing = threading.Thread(target=view.close, daemon=True)
    closing.start()
    closing.join(5)
    return not closing.is_alive(), steps


def test_a_keyboard_interrupt_anywhere_in_feeding_the_view_leaves_its_close_prompt() -> None:
    """The caller feeds the view from the main thread, where an ending signal raises
    KeyboardInterrupt between any two steps: none of them may leave a lock held (a
    queue's, which once hung the board's exit for good)."""
    step = 0
    while True:
        step += 1
        closed, steps = _feed_interrupted_at(step)
        assert closed, f"close waits for good after an interrupt at step {step}"
        if steps < step:  # the feed ran to its end before the interrupt was due
            break
    assert step > 3
