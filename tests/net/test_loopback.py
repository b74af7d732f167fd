"""A shared car reached over this machine's loopback (no namespaces needed): TLS and its
certificate, a router between client and car, the ports a share's stop goes to, the
pytest plugin on a zenoh:// URL — each judged on the board's own recording."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path
from typing import Any

import pytest

from appmode.web.certificate import own_certificate
from tests.support.processes import run, scripted, wait_for
from tests.support.shares import KEY, routed, shared_board
from tests.testing.test_plugin import pytest_in

pytest.importorskip("zenoh", reason="the net extra (eclipse-zenoh) is not installed")


def test_tls_checks_the_key_and_needs_the_share_s_certificate(tmp_path: Path) -> None:
    with shared_board(tmp_path, "car", "--tls") as car:
        assert "connect=tls/127.0.0.1:" in car.url
        cert = tmp_path / "data" / "appmode" / "share-cert.pem"
        stale, _ = own_certificate(["127.0.0.1"], tmp_path, server="stale")  # another's
        done = run("params", f"{car.url}&ca={cert}", "--json")
        assert done.returncode == 0 and '"max_speed": 500' in done.stdout, done.stderr
        for url, said in (
            (car.url, "a tls/ endpoint needs the share's certificate: add &ca=FILE"),
            (f"{car.url}&ca={tmp_path / 'none.pem'}", "no such file"),
            (f"{car.url.replace('key=fleet', 'key=wrong')}&ca={cert}", "refused this key"),
            (f"{car.url}&ca={stale}", f"its certificate is not the one in ca={stale}"),
        ):
            refused = run("params", url)
            assert refused.returncode == 2 and said in refused.stderr, refused.stderr
            assert len(refused.stderr.splitlines()) == 1
        err = car.stop()
    assert "a client needs this share's certificate" in err and "fingerprint" in err


def test_a_car_through_a_router_is_driven_and_listed(tmp_path: Path) -> None:
    with routed(tmp_path) as (endpoint, car):
        listed = run("fleet", "--connect", endpoint, "--key", KEY, "--json")
        assert '"name": "car"' in listed.stdout, listed.stderr
        url = f"zenoh://car?connect={endpoint}&key={KEY.replace(' ', '%20')}"
        done = run("send", url, "J", "A", "wait:0.5")
        assert done.returncode == 0, done.stderr
        assert "A" in car.sent() and car.sent()[-1] == "Z", car.sent()


def test_a_share_stops_only_the_ports_used_so_letters_still_drive_after(tmp_path: Path) -> None:
    """A zero frame on the control port takes the motion over from the APP port for good
    (§8.3): a share whose clients drove with letters never sends one."""
    with shared_board(tmp_path, "car", uart2=True) as car:
        for _ in range(2):
            done = run("send", car.url, "J", "A", "wait:1.2", "--json")
            assert done.returncode == 0, done.stderr
            assert '"y": 500' in done.stdout, "the car did not move on its letters"
        car.stop()
        assert not [line for line in car.record.read_text().splitlines() if " 2> " in line]
        assert car.sent()[-1] == "Z"


def test_the_pytest_plugin_runs_against_a_shared_car(tmp_path: Path) -> None:
    project = tmp_path / "project"
    project.mkdir()
    (project / "pytest.ini").write_text("[pytest]\n")
    (project / "test_car.py").write_text(
        "import serial\n\n"
        "def test_records(appmode_board):\n"
        "    with serial.serial_for_url(appmode_board.port, 9600, timeout=1) as port:\n"
        "        port.write(b'{Q:P}')\n"
        "        assert b'{C' in port.read_until(b'{C', 400)\n\n"
        "def test_drive(appmode_board):\n"
        "    with serial.serial_for_url(appmode_board.port, 9600, timeout=1) as port:\n"
        "        port.write(b'JA')\n"
        "        port.read(200)\n"
    )
    with shared_board(tmp_path, "car") as car:
        done = pytest_in(project, "--appmode-board", car.url)
        assert done.returncode == 0, done.stdout + done.stderr
        assert "2 passed" in done.stdout
        assert car.sent()[-1] == "Z", "the plugin's stop after the test that drove"
        wrong = pytest_in(project, "--appmode-board", car.url.replace("key=fleet", "key=guess"))
        assert wrong.returncode == 4 and "key=…" in wrong.stderr and "guess" not in wrong.stderr


def test_what_a_hostile_car_s_host_says_is_shown_escaped_and_never_breaks_the_fleet() -> None:
    """A car's host (it holds the host key: it signs) answering with terminal escapes, a
    driver that is not an object, and no JSON at all: `fleet` lists what it can, escaped,
    in one piece; a name no share could take (escapes, 2,000 characters: issue 80.12) is
    no car."""
    import zenoh

    from appmode.net.config import close_session, free_port, open_session
    from appmode.net.signature import Signer

    signer = Signer("a hostile room's host key")

    endpoint = free_port("tcp/127.0.0.1:0")
    evil = "evil\x1b]52;c;bm9wZQ==\x07\x1b[2J"
    answers = {
        "appmode/evil-car/info": {"profile": evil, "battery": "\x1b[8m", "driver": "x"},
        f"appmode/{evil}/info": {"profile": "named with escapes"},
        f"appmode/{'x' * 2000}/info": {"profile": "named too long"},
        "appmode/junk/info": None,
    }
    session = open_session("peer", KEY, listen=(endpoint,))

    def answer(query: zenoh.Query) -> None:
        for key, body in answers.items():
            signer.reply(query, key, "{not json" if body is None else json.dumps(body))

    queryable = session.declare_queryable("appmode/*/info", answer)
    try:
        listed = run("fleet", "--connect", endpoint, "--key", KEY, "--id", signer.id)
    finally:
        queryable.undeclare()
        close_session(session)
    assert listed.returncode == 0, listed.stderr
    assert "\x1b" not in listed.stdout and "\x07" not in listed.stdout
    assert "evil\\x1b]52;c;bm9wZQ==\\x07\\x1b[2J" in listed.stdout, listed.stdout
    assert "named with escapes" not in listed.stdout and "named too long" not in listed.stdout
    assert len(listed.stdout) < 1000, "one car's line, and the header"
    assert "junk" not in listed.stdout and "Traceback" not in listed.stderr


def test_sharing_a_port_that_is_not_there_is_one_line() -> None:
    """Issue 79.6: `share /dev/ttyUSB0` with no adapter plugged in ended in `internal error:
    StopIteration` (a second error in Share.close hid the real one)."""
    done = run(
        "share", "/dev/ttyNOSUCH0", "--key", "k", "--name", "car",
        "--listen", "tcp/127.0.0.1:0",  # 7450 may be another run's
        timeout=60,
    )  # fmt: skip
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1, done.stderr
    assert "no such port /dev/ttyNOSUCH0" in lines[0] and "internal error" not in lines[0]


def test_a_forged_car_name_or_field_makes_no_long_fleet_table() -> None:
    """Issue 80.12: a key holder's info reply under a 20,000-character name made a 100 kB
    `fleet` table. A name no share could take is no car; a cell is cut at 40."""
    from appmode.cli.fleet import table
    from appmode.net.fleet import Car

    long = "x" * 20_000
    shown = table([Car("car-1", {"profile": long, "machine": "\x1b[2J" + long}, 1.0)])
    assert len(shown) < 500 and "\x1b" not in shown and "…" in shown


def test_the_page_and_the_share_keep_certificates_of_their_own(tmp_path: Path) -> None:
    """Issue 79.6/80.12: `web --listen 0.0.0.0` made a new certificate in the file the
    share served, and every client's `ca=` copy stopped working."""
    from tests.support.web import web_process

    with shared_board(tmp_path, "car", "--tls") as car:
        cert = tmp_path / "data" / "appmode" / "share-cert.pem"
        held = cert.read_bytes()
        with web_process(tmp_path, "--listen", "0.0.0.0:0"):
            pass
        assert (tmp_path / "data" / "appmode" / "web-cert.pem").is_file()
        assert cert.read_bytes() == held, "the page's certificate is not the share's"
        done = run("params", f"{car.url}&ca={cert}", "--json")
        assert done.returncode == 0, done.stderr


def test_a_shared_car_whose_serial_link_is_down_is_said_so_remotely(tmp_path: Path) -> None:
    """Issue 79.6: params of a shared car whose board is gone says the car's host lost
    its serial link, not to check the baud rate."""
    with shared_board(tmp_path, "car") as car:
        car.board.proc.kill()
        car.board.proc.wait()
        done = run("params", car.url)
        car.stop()
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1, done.stderr
    assert "the car's host has lost its serial link to the car" in done.stderr
    assert "baud rate" not in done.stderr


def test_a_link_lost_before_a_client_subscribed_is_said_by_the_share_s_info(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The car's host says a lost link once, as an event: a client opening between its
    info and its subscribing missed it (beside a second run of the suite, `params` then
    advised the baud rate). The info it publishes every second says it too."""
    from appmode.net.remote_port import LINK_DOWN, RemoteSerial
    from appmode.ports.urls import open_link

    said = RemoteSerial._on_event

    def missing_link_events(port: RemoteSerial, sample: Any) -> None:
        if b'"t": "link"' not in sample.payload.to_bytes():
            said(port, sample)

    monkeypatch.setattr(RemoteSerial, "_on_event", missing_link_events)
    with shared_board(tmp_path, "car") as car:
        port = open_link(car.url)
        try:
            assert getattr(port, "car_link_down", "") is None
            car.board.proc.kill()
            car.board.proc.wait()
            wait_for(lambda: getattr(port, "car_link_down", None) == LINK_DOWN, 5)
        finally:
            port.close()
        car.stop()


def _ended(proc: subprocess.Popen[str]) -> tuple[str, str]:
    assert proc.stdin is not None and proc.stdout is not None and proc.stderr is not None
    proc.stdin.close()
    out, err = proc.stdout.read(), proc.stderr.read()
    proc.wait(30)
    return out, err


@pytest.mark.parametrize("ending", ["SIGTERM", "SIGKILL"])
def test_a_driver_is_told_truly_how_its_share_ended(ending: str, tmp_path: Path) -> None:
    """Issue 80.12: a share that ends (SIGTERM) stops the car first and its driver says
    so, with no "may still be moving"; one killed leaves the car as it was, and says so."""
    import time

    with shared_board(tmp_path, "car") as car:
        driver = scripted(car.url, "drive A\nwait 4\n")
        time.sleep(2.5)
        if ending == "SIGKILL":
            car.share.kill()
        car.stop()
        out, err = _ended(driver)
        sent = car.sent()
    if ending == "SIGTERM":
        assert sent[-1] == "Z", sent
        assert "the car's host ended its share of car: it stopped the car first" in out
        assert driver.returncode == 0 and "may still be moving" not in err, err
    else:
        assert sent[-1] == "A", sent  # the board's own recording: nobody stopped it
        assert "was killed, or its machine or network is down" in out
        assert driver.returncode == 1 and "may still be moving" in err


def test_a_take_over_is_said_as_the_hosts_stop_not_as_the_control_port(tmp_path: Path) -> None:
    """Issue 80.12: the driver taken over is told why, and no "UART2 may have taken over"
    follows; the one that took it is told the car's host stopped the car."""
    import time

    with shared_board(tmp_path, "car") as car:
        first = scripted(car.url, "drive A\nwait 5\n")
        time.sleep(2)
        second = scripted(f"{car.url}&take=1", "wait 3\n")
        out, _ = _ended(first)
        taken, _ = _ended(second)
        sent = car.sent()
    assert "took the driving over" in out and "may have taken over" not in out, out
    assert re.search(r"the car's host stopped the car: \S+ took the driving over", taken), taken
    assert "A" in sent and sent[-1] == "Z"
