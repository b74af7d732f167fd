"""A WHEELTEC car's chassis port shared over Zenoh: a client drives it as a local one
(the velocity re-sent while it drives, a zero frame at its end), judged on the board's
recording, and the share's stop authority ends the motion when the client goes."""

from __future__ import annotations

import signal
import subprocess
import time
from pathlib import Path

import pytest

pytest.importorskip("zenoh", reason="the net extra (eclipse-zenoh) is not installed")

from appmode.protocol import chassis
from appmode.protocol.twist import Twist
from tests.support.processes import appmode_cmd, board_process, run, serving, stop_process

KEY = "chassis key"
MOVING = chassis.command(Twist(0.3)).hex(" ").upper()
STOP = chassis.STOP.hex(" ").upper()


def sent(record: Path) -> list[tuple[float, str]]:
    lines = record.read_text().splitlines() if record.exists() else []
    return [(float(line.split()[0]), line.split(" c> ", 1)[1]) for line in lines if " c> " in line]


@pytest.mark.timing  # the frame re-sent 8 times while it drove: 7 when starved
def test_a_shared_chassis_is_driven_and_stopped_by_its_share(tmp_path: Path) -> None:
    profile = tmp_path / "quick.toml"
    profile.write_text(
        'name = "quick"\nlike = "wheeltec-mec"\n[chassis]\nkind = "mec"\nboot_ms = 300\n'
    )
    record = tmp_path / "board.transcript"
    with board_process(
        "--pty", "--quiet", "--record", str(record), "--profile", str(profile)
    ) as board:
        assert board.chassis is not None
        share, line = serving(
            "share", board.chassis, "--chassis", "--profile", str(profile), "--name", "wt",
            "--listen", "tcp/127.0.0.1:0", "--key", KEY, data=tmp_path / "data",
        )  # fmt: skip
        try:
            url = line.strip().replace("key=…", f"key={KEY}") + "&port=chassis"
            assert url.startswith("zenoh://wt?"), f"{line!r}: {stop_process(share)}"
            done = run("send", url, "--chassis", "--profile", str(profile),
                       "velocity:0.3", "wait:1", "--listen", "0")  # fmt: skip
            assert done.returncode == 0, done.stderr
            assert "status +0.30 m/s" in done.stdout, "the car's status came back over Zenoh"
            frames = [frame for _, frame in sent(record)]
            assert frames.count(MOVING) >= 8, "re-sent while it drove"
            assert frames[-1] == STOP
            # a client killed while driving: the share's stop authority stops the car
            client = subprocess.Popen(
                appmode_cmd(
                    "send", url, "--chassis", "--profile", str(profile), "velocity:0.3", "wait:30"
                ),
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            end = time.monotonic() + 20
            while time.monotonic() < end and (not sent(record) or sent(record)[-1][1] != MOVING):
                time.sleep(0.05)
            client.send_signal(signal.SIGKILL)
            client.wait()
            killed = time.monotonic()
            while time.monotonic() < killed + 5 and sent(record)[-1][1] != STOP:
                time.sleep(0.05)
            assert sent(record)[-1][1] == STOP, "the share stopped the car its client left"
        finally:
            err = stop_process(share)
    assert "Traceback" not in err, err
