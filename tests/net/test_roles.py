"""Issue 80.4 and 80.5: a key holder can drive a car it is given, and nothing more. It
cannot keep a dead driver's car moving (heartbeats and a token under the driver's id),
drive under the driver's id, answer as the car (info, stop, a `**` queryable), nor
publish the car's events; judged on the board's own recording."""

from __future__ import annotations

import json
import signal
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from appmode.net.names import Keys
from tests.support.processes import run, scripted, timed_sent, wait_for
from tests.support.shares import KEY, SharedBoard, routed, shared_board

pytest.importorskip("zenoh")

FORGED_INFO = {"name": "car", "driver": None, "moving": False, "in_force": None}


class Forger:
    """A key holder speaking for the driver — it echoes each heartbeat it hears, beats
    under the driver's id (on Zenoh, and on UDP to `beats`), holds the driver's token
    and writes under its id, every 50 ms — and for the car (`begin`)."""

    def __init__(self, endpoint: str, beats: str | None = None) -> None:
        from appmode.net.beats import BeatSender
        from appmode.net.config import open_session

        self.keys = Keys("car")
        self.session = open_session("client", KEY, connect=(endpoint,))
        self.heard: list[str] = []
        self._datagrams = BeatSender(() if beats is None else (beats,))
        """To the car's host's heartbeat port (`net.beats`), when given."""
        self.refusals: list[str] = []
        self._token: Any = None
        self._done = threading.Event()
        self._begun = threading.Event()
        self._as_car = False
        keys = self.keys

        self._declared = [self.session.declare_subscriber(keys.alive, self._on_alive)]
        self._thread = threading.Thread(target=self._forge, daemon=True)
        self._thread.start()

    def _on_alive(self, sample: Any) -> None:
        self.heard.append(sample.payload.to_string())

    @property
    def driver(self) -> str | None:
        """The id its last heartbeat gave, once the forging began (`begin`)."""
        return self.heard[-1].split(" ")[0] if self.heard and self._begun.is_set() else None

    def begin(self, as_car: bool = False) -> None:
        """Forge from now on (the car driven: the driver holds the lease); `as_car`, as
        the car too: its events, and answers to its info and stop (and to `**`)."""
        import zenoh

        def answer(query: zenoh.Query) -> None:
            body = {**FORGED_INFO, "sent": True, "confirmed": True}
            query.reply(str(query.key_expr), json.dumps(body))

        keys = self.keys
        self._as_car = as_car
        for key in (keys.info, keys.stop, "**") if as_car else ():
            self._declared.append(self.session.declare_queryable(key, answer))
        self._begun.set()

    def _forge(self) -> None:
        keys, session = self.keys, self.session
        while not self._done.wait(0.05):
            driver = self.driver
            if driver is None:
                continue
            if self._token is None:
                self._token = session.liveliness().declare_token(keys.driver(driver))
            session.put(keys.alive, self.heard[-1])  # the driver's own, replayed
            session.put(keys.alive, f"{driver} 99999 {'0' * 32}")
            session.put(keys.alive, driver)
            self._datagrams.send(f"car {self.heard[-1]}")
            self._datagrams.send(f"car {driver}")
            session.put(
                keys.events, json.dumps({"t": "dropped", "client": driver, "why": "FORGED"})
            )
            session.put(keys.info, json.dumps(FORGED_INFO))
            for reply in session.get(
                keys.write("app"), payload=b"A", attachment=f"{driver} 1e9 99999 {'0' * 32}"
            ):
                said = reply.ok.payload.to_string() if reply.ok is not None else "{}"
                if "refused" in json.loads(said):
                    self.refusals.append(said)

    def close(self) -> None:
        from appmode.net.config import close_session

        self._done.set()
        self._thread.join(5)
        self._datagrams.close()
        close_session(self.session)


def _z_after_a(car: SharedBoard) -> float:
    """When (this machine's clock, at the latest) the board took Z after its last A."""
    timed = timed_sent(car.record)
    last = max(i for i, (_, unit) in enumerate(timed) if unit == "A")
    return car.board.clock_after + next(t for t, unit in timed[last + 1 :] if unit == "Z")


def _url(endpoint: str) -> str:
    return f"zenoh://car?connect={endpoint}&key={KEY.replace(' ', '%20')}"


def test_a_key_holder_keeps_no_dead_driver_s_car_moving(tmp_path: Path) -> None:
    """Issue 80.4: heartbeats under the driver's id and a token on its key kept the car
    moving 5.9–7.0 s after the driver's SIGKILL. The driver's heartbeats carry a proof
    under a secret only its grant's reply held: the forger's renew nothing, its writes
    under the driver's id are refused, and the car stops as if it were not there."""
    with routed(tmp_path) as (endpoint, car):
        forger = Forger(endpoint, beats=car.endpoint)
        try:
            driver = scripted(_url(endpoint), "drive A\nwait 30\n")
            wait_for(lambda: "A" in car.sent(), 30)
            forger.begin()
            time.sleep(1.5)  # the forger at work, the car driven on
            refused = list(forger.refusals)  # while the driver lived
            killed = time.monotonic()
            driver.kill()
            driver.wait(10)
            wait_for(lambda: car.sent()[-1] == "Z", 10)
            stopped_after = _z_after_a(car) - killed
        finally:
            forger.close()
    assert stopped_after < 1.0, f"Z {stopped_after:.2f} s after the driver's SIGKILL"
    assert refused and all("not the driver's" in r for r in refused), refused


@pytest.mark.parametrize("through", ["router", "share"])
def test_a_key_holder_does_not_speak_for_the_car(through: str, tmp_path: Path) -> None:
    """Issue 80.5: a key holder's info reply replaced the car's, its stop reply said
    "stopped (confirmed)" for a car whose host was killed, and its "dropped" event
    kicked the driver. The car's host and the router let no key holder's answer or
    event through (Zenoh's access control, the host key): the car is shown as it is,
    the driver drives on, and a stop nobody could make is said to be unconfirmed. Key
    holders connect to the router, or to the car's host itself."""
    with routed(tmp_path) as (router, car):
        endpoint = router if through == "router" else car.endpoint
        forger = Forger(endpoint)
        try:
            driver = scripted(_url(endpoint), "drive A\nwait 3\n")
            wait_for(lambda: "A" in car.sent(), 30)
            forger.begin(as_car=True)
            fleet = run("fleet", "--connect", endpoint, "--key", KEY, "--json")
            listed = json.loads(fleet.stdout)
            driver.stdin.close()  # type: ignore[union-attr]
            out = driver.stdout.read()  # type: ignore[union-attr]
            driver.wait(30)
            assert driver.returncode == 0 and "FORGED" not in out, out
            assert [c["driver"]["client"] for c in listed] == [forger.driver], listed
            car.share.send_signal(signal.SIGKILL)
            car.share.wait(10)
            stop = run("fleet", "stop", "--connect", endpoint, "--key", KEY)
        finally:
            forger.close()
    assert stop.returncode != 0 and "confirmed" not in stop.stdout, stop.stdout + stop.stderr


def test_a_share_of_another_host_key_is_refused_and_says_so(tmp_path: Path) -> None:
    """Shares that connect to each other need one host key: one with another is refused
    (the first logs it) and says it has not joined, in a line each; one with the same
    joins quietly and is listed beside the first."""
    with shared_board(tmp_path, "car-a") as first:
        with shared_board(
            tmp_path, "car-b", "--connect", first.endpoint, "--host-key", "another"
        ) as stranger:
            err = stranger.stop()
        with shared_board(tmp_path, "car-c", "--connect", first.endpoint) as joined:
            listed = run("fleet", "--connect", first.endpoint, "--key", KEY, "--json")
            quiet = joined.stop()
        said = first.stop()
    assert "not joined" in err and "--host-key" in err, err
    assert "a host key not this one's" in said, said
    assert "not joined" not in quiet, quiet
    assert [car["name"] for car in json.loads(listed.stdout)] == ["car-a", "car-c"], listed
