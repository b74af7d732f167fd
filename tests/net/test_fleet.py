"""Twenty cars on one host in `appmode fleet` (issue 66.7), found from a laptop on the
same LAN by scouting alone — inside network namespaces, never on this machine's own
interfaces — and stopped at once, each car's host confirming its stop."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.netns import lan, why_not
from tests.support.processes import ROOT, run, stop_process

pytest.importorskip("zenoh", reason="the net extra (eclipse-zenoh) is not installed")
WHY = why_not()
pytestmark = pytest.mark.skipif(WHY is not None, reason=f"no network namespaces: {WHY}")
CARS = 20
KEY = "room key"


@pytest.mark.alone  # twenty simulated cars keep a core busy: no timing test beside them
def test_twenty_cars_on_one_host_are_found_by_scouting_and_stopped_together() -> None:
    with lan("cars", "laptop") as machines:
        host = subprocess.Popen(
            machines["cars"].command(
                sys.executable, "-m", "tests.support.many_cars", str(CARS), "tcp/0.0.0.0:7450", KEY
            ),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        try:
            assert host.stdout is not None and host.stdout.readline().strip() == "ready"
            laptop = machines["laptop"]
            listed = laptop.run("fleet", "--key", KEY, "--json")
            assert listed.returncode == 0, listed.stderr
            cars = json.loads(listed.stdout)
            assert [car["name"] for car in cars] == [f"car-{n:02}" for n in range(1, CARS + 1)]
            assert all(car["battery"] == 100 and car["simulated"] for car in cars)
            table = laptop.run("fleet", "--key", KEY)
            assert len(table.stdout.splitlines()) == CARS + 1 and "car-20" in table.stdout
            stopped = laptop.run("fleet", "stop", "--key", KEY)
            assert stopped.returncode == 0, stopped.stdout + stopped.stderr
            assert stopped.stdout.count("stopped (confirmed)") == CARS, stopped.stdout
            stranger = laptop.run("fleet", "--key", "not the key", "--json")
            assert stranger.stdout.strip() == "" and stranger.returncode == 2, stranger.stdout
            assert "found no car's host on this network with this key" in stranger.stderr
        finally:
            err = stop_process(host)
        assert host.returncode == 0 and "Traceback" not in err, err


def test_fleet_without_a_key_says_where_a_key_comes_from(tmp_path: Path) -> None:
    """Issue 79.6: no --key and no share key of this machine's: one line, and no key is
    made (a new one would match no car)."""
    done = run("fleet", env={"XDG_DATA_HOME": str(tmp_path)})
    assert done.returncode == 2 and "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("appmode: error: fleet: no key: give the cars' key with --key KEY")
    assert str(tmp_path / "appmode" / "share.key") in line
    assert not (tmp_path / "appmode").exists()
