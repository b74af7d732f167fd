"""The car as a ROS 2 node (issue 67): `appmode ros` on a simulated board served on two
ptys, a Zenoh router on loopback, and a ROS side (tests/ros/peer.py) publishing
cmd_vel at 20 Hz and reading odom (python -m bench.ros).

- cmd_vel → byte: a Twist published until its velocity frame is on the board's control
  port, read off the board's own recording (each Twist's speed differs by 1 mm/s, so
  each frame names the Twist it came from);
- odometry: its rate, and its delay from the host's decoding of an A record (the
  message's stamp) to the ROS side's receipt;
- the node's CPU (all its threads) while it drives and publishes.
"""

from __future__ import annotations

import argparse
import os
import socket
import statistics
import tempfile
import threading
import time
from pathlib import Path

from appmode.net.config import close_session
from appmode.testing.process import BoardProcess
from bench.common import Row, cpu_share, percentile
from tests.ros import peer
from tests.support.processes import serving, stop_process

RATE = 20.0
"""cmd_vel samples a second, as teleop and Nav2 send them."""


def _endpoint() -> str:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{probe.getsockname()[1]}"


def _frames(record: Path) -> dict[int, float]:
    """Each velocity frame's y (mm/s) → when the board first took it (its clock)."""
    first: dict[int, float] = {}
    for line in record.read_text().splitlines():
        if " 2> FF FE 01 " not in line:
            continue
        when, frame = line.split(" 2> ", 1)
        data = bytes.fromhex(frame)
        first.setdefault(int.from_bytes(data[5:7], "big"), float(when.split()[0]))
    return first


def measure(seconds: float) -> list[Row]:
    endpoint = _endpoint()
    router = peer.router(endpoint)
    with tempfile.TemporaryDirectory() as folder:
        record = Path(folder) / "board.transcript"
        board = BoardProcess("--pty", "--quiet", "--record", str(record))
        node, line = serving(
            "ros", board.url, board.uart2, "--connect", endpoint, data=Path(folder)
        )
        ros = peer.session(endpoint)
        try:
            if not line.startswith("ros: node"):
                raise SystemExit(f"appmode ros did not start: {line!r} {stop_process(node)}")
            time.sleep(2)
            entities = {e.topic: e for e in peer.graph(ros)}
            odometry = peer.Received()
            arrived: list[int] = []

            def on_odom(sample: object) -> None:
                arrived.append(time.time_ns())
                odometry.on_sample(sample)  # type: ignore[arg-type]

            subscriber = ros.declare_subscriber(entities["/odom"].data_key, on_odom)
            twist = peer.TwistPublisher(ros, entities["/cmd_vel"])
            sent: dict[int, float] = {}
            shares: list[float] = []
            measuring = threading.Thread(
                target=lambda: shares.append(cpu_share(node.pid, seconds - 2)), daemon=True
            )
            start = time.monotonic()
            k = 0
            while time.monotonic() - start < seconds:
                speed = 100 + k % 400  # mm/s: each Twist's own frame
                sent.setdefault(speed, time.monotonic())
                twist.publish(speed / 1000)
                k += 1
                time.sleep(1 / RATE)
                if k == int(RATE):  # after a second of driving
                    measuring.start()
            measuring.join()
            cpu = shares[0]
            subscriber.undeclare()  # type: ignore[no-untyped-call]
        finally:
            close_session(ros)
            stop_process(node)
            board.stop()
            close_session(router)
        frames = _frames(record)
    latency = [board.clock_after + frames[y] - t for y, t in sent.items() if y in frames]
    stamps = [m.header.stamp for m in odometry.messages("nav_msgs/msg/Odometry")]
    delays = [
        (got - (s.sec * 10**9 + s.nanosec)) / 1e6 for got, s in zip(arrived, stamps, strict=False)
    ]
    rate = len(arrived) / seconds
    p99 = percentile(latency, 99) * 1000
    return [
        Row(
            "ros: cmd_vel -> velocity frame on the board (20 Hz Twists)",
            f"median {statistics.median(latency) * 1000:.2f} ms, p99 {p99:.2f} ms "
            f"(n={len(latency)} of {len(sent)})",
            "p99 < 10 ms",
            p99 < 10,
        ),
        Row(
            "ros: odom rate and delay (the host's decoding to the ROS side)",
            f"{rate:.1f} Hz; median {statistics.median(delays):.2f} ms, "
            f"p99 {percentile(delays, 99):.2f} ms",
            "10 Hz (the board's A records), p99 < 10 ms",
            abs(rate - 10) < 1.5 and percentile(delays, 99) < 10,
        ),
        Row(
            "ros: the node's CPU (driving at 20 Hz, publishing odom, tf, imu, battery)",
            f"{cpu:.1f} % of a core (the simulated board's own process apart)",
            "< 25 % of a core",
            cpu < 25,
        ),
    ]


def rows(quick: bool) -> list[Row]:
    return measure(8.0 if quick else 30.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    for row in rows(args.quick):
        print(f"{row.benchmark}: {row.result} (target {row.target}: {row.met})")


if __name__ == "__main__":
    main()
