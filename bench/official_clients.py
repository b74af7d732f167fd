"""appmode held to the official clients from npm (issue 78), as CI runs it:

    npm install --prefix DIR @foxglove/ws-protocol @mcap/core @foxglove/wasm-zstd ws
    python -m bench.official_clients --modules DIR/node_modules

A simulated board records what it gets; `appmode drive` serves its session with
`--foxglove-drive` and records it as MCAP. @foxglove/ws-protocol's FoxgloveClient lists
the parameters, advertises /cmd_vel and publishes 0.3 m/s for 2 s, then sets max_speed
to 800; the board's recording must show the motion, its stop within 0.8 s of the last
twist, and the set. @mcap/core's McapIndexedReader then reads the recording through its
index: every message, wall-clock times, a schema on every channel, /log and
/session/in_force. Exit status 1, a line a failure, when any of it does not hold."""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from appmode.testing.process import board_process

HERE = Path(__file__).resolve().parent
SCRIPT = HERE / "official" / "clients.mjs"
ROOT = HERE.parent
APPMODE = (sys.executable, "-m", "appmode")
SERVE = ("--foxglove", "0", "--foxglove-drive")


def node(modules: Path, *args: str) -> dict[str, object]:
    """The script's JSON line, run where `modules` (a node_modules folder) resolves."""
    done = subprocess.run(
        ["node", str(SCRIPT), *args],
        cwd=modules.parent,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    if done.returncode != 0:
        raise SystemExit(f"official_clients: node {args[0]} failed: {done.stderr.strip()[-400:]}")
    result: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def drive(modules: Path, folder: Path) -> list[str]:
    """FoxgloveClient drives and tunes; what the board's recording does not show."""
    record, mcap = folder / "board.txt", folder / "drive.mcap"
    failures: list[str] = []
    with board_process("--record", str(record), cwd=ROOT) as board:
        session = subprocess.Popen(
            [*APPMODE, "drive", board.url, *SERVE, "--record", str(mcap)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        assert session.stdin is not None and session.stderr is not None
        line = ""
        while "ws://" not in line:
            line = session.stderr.readline()
            if not line:
                raise SystemExit("official_clients: the session said no ws:// URL")
        url = re.search(r"ws://\S+", line)
        assert url is not None
        session.stdin.write("wait 12\n")
        session.stdin.close()
        said = node(modules, "drive", url.group(0))
        session.wait(30)
        clock = board.clock_after
    sent = [
        (float(t), payload)
        for t, d, payload in (
            ln.split(" ", 2) for ln in record.read_text().splitlines() if " > " in ln
        )
        if d == ">"
    ]
    capabilities = said["capabilities"]
    assert isinstance(capabilities, list)
    if "clientPublish" not in capabilities or "parameters" not in capabilities:
        failures.append(f"serverInfo offers {capabilities}: no clientPublish or parameters")
    listed = said["listed"]
    assert isinstance(listed, list)
    if len(listed) != 9 or "max_speed" not in listed:
        failures.append(f"getParameters listed {listed}")
    starts = [t for t, p in sent if p == "A"]
    stops = [t for t, p in sent if p == "Z" and starts and t > starts[0]]
    last = said["last"]
    assert isinstance(last, float)
    if not starts or not stops:
        failures.append(f"the board got no forward motion and stop: {[p for _, p in sent]}")
    else:
        wall = time.time() - time.monotonic()  # the board's clock is monotonic, node's the wall
        late = clock + stops[0] - (last - wall)
        drove = stops[0] - starts[0]
        print(f"official_clients: A for {drove:.2f} s, Z {late:.2f} s after the last twist")
        if late > 0.8:
            failures.append(f"the board's Z came {late:.2f} s after the last twist (over 0.8 s)")
    if "{0:800}" not in [p for _, p in sent]:
        failures.append("setParameters max_speed=800 never reached the board")
    return failures + read(modules, mcap)


def read(modules: Path, mcap: Path) -> list[str]:
    """McapIndexedReader reads the recording whole; what it does not find."""
    found = node(modules, "mcap", str(mcap))
    print(
        f"official_clients: McapIndexedReader: {found['count']} messages, {found['chunks']} chunks"
    )
    failures = []
    if found["count"] != found["statistics"] or not found["count"]:
        failures.append(f"{found['count']} messages read of {found['statistics']}")
    first, last = found["first"], found["last"]
    assert isinstance(first, float) and isinstance(last, float)
    if abs(first - time.time()) > 60 or abs(last - time.time()) > 60:
        failures.append(f"log times {first:.0f}–{last:.0f} are not within a minute of the clock")
    if found["schemaless"]:
        failures.append(f"channels with no schema: {found['schemaless']}")
    topics = found["topics"]
    assert isinstance(topics, dict)
    for topic in ("/log", "/session/in_force", "/raw/app/sent"):
        if not topics.get(topic):
            failures.append(f"no {topic} messages in the recording")
    return failures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--modules", type=Path, required=True, help="a node_modules folder")
    args = parser.parse_args()
    modules = args.modules.resolve()
    with tempfile.TemporaryDirectory() as folder:
        os.chdir(folder)
        failures = drive(modules, Path(folder))
    for failure in failures:
        print(f"official_clients: FAILED: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
