"""The ROS tests' car: a simulated board, `appmode ros` serving it through a Zenoh
router on loopback, and a ROS 2 side (tests/ros/peer.py) in a session of that router."""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

pytest.importorskip("zenoh", reason="the ros extra (eclipse-zenoh) is not installed")
pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")

import zenoh

from appmode.testing.process import BoardProcess
from tests.ros import peer
from tests.support.processes import serving, stop_process, timed_sent


@dataclass
class Car:
    board: BoardProcess
    record: Path
    node: object
    ros: zenoh.Session
    endpoint: str

    def frames(self) -> list[tuple[float, str]]:
        """The control port's frames as the board took them (its clock), in hex."""
        lines = self.record.read_text().splitlines() if self.record.exists() else []
        return [
            (float(line.split()[0]), line.split(" 2> ", 1)[1]) for line in lines if " 2> " in line
        ]

    def board_timed(self) -> list[tuple[float, str]]:
        """What the board took on its APP port, with its times."""
        return timed_sent(self.record) if self.record.exists() else []

    def board_sent(self) -> list[str]:
        return [unit for _, unit in self.board_timed()]

    def entities(self, want: int) -> list[peer.Entity]:
        """The node's entities once the graph holds `want` of them and has stopped
        growing (its tokens do not come in one order: the eighth may be `/odom`)."""
        end, seen = time.monotonic() + 15, -1
        while time.monotonic() < end:
            found = peer.graph(self.ros)
            if len(found) >= want and len(found) == seen:
                return found
            seen = len(found)
            time.sleep(0.3)
        raise AssertionError(f"the graph holds {peer.graph(self.ros)}")


def free_endpoint() -> str:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{probe.getsockname()[1]}"


@pytest.fixture
def car(tmp_path: Path, request: pytest.FixtureRequest) -> Iterator[Car]:
    uart2, *extra = getattr(request, "param", (True,))
    endpoint = free_endpoint()
    router = peer.router(endpoint)
    record = tmp_path / "board.transcript"
    at = extra.index("--profile") if "--profile" in extra else len(extra)
    board = BoardProcess("--pty", "--quiet", "--record", str(record), *extra[at : at + 2])
    node, line = serving(
        "ros",
        board.url,
        *((board.uart2,) if uart2 else ()),
        "--connect",
        endpoint,
        *extra,
        data=tmp_path / "data",
    )
    ros = peer.session(endpoint)
    try:
        assert line.startswith("ros: node /appmode"), f"{line!r}: {stop_process(node)}"
        yield Car(board, record, node, ros, endpoint)
    finally:
        ros.close()
        stop_process(node)
        board.stop()
        router.close()
