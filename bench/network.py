"""A car on the network (issue 66): what sharing it over Zenoh adds, across a veth pair
between two network namespaces (the car's host and a laptop), against the same host on
the car's own machine (python -m bench.network; needs root for the namespaces).

- key-to-byte: a host's send of a letter until the byte is read off the car's serial
  line — a pty this benchmark holds, playing the car — locally and from the laptop; the
  overhead is the remote p99 less the local p99.
- telemetry delay: a record written to the car's line until the host has decoded it.
- CPU per car: the sharing host's share of a core per car, ten simulated cars shared
  from one process, with nobody and then with a client watching one.
- fifty cars: `appmode fleet --json` on the laptop listing fifty cars shared from one
  host, found by scouting.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import threading
import time
import tty
from collections.abc import Iterator
from contextlib import contextmanager

from bench.common import Row, cpu_share, percentile
from tests.support.netns import Machine, lan, why_not

KEY = "bench key"
SLOT = 0.05
"""The car's telemetry period (seconds)."""
LETTERS = b"ABCDEFGH"


# ---------------------------------------------------------------- the car: a pty held here


class Car:
    """A car's serial line as a pty: records written every SLOT seconds, numbered, and
    the letters read off it, each with its time (this machine's monotonic clock, which
    every namespace shares)."""

    def __init__(self) -> None:
        self.master, slave = os.openpty()
        tty.setraw(slave)
        self.path = os.ttyname(slave)
        self._slave = slave
        self.written: dict[int, float] = {}
        self.letters: list[float] = []
        self._ended = threading.Event()
        self._threads = [
            threading.Thread(target=self._write, daemon=True),
            threading.Thread(target=self._read, daemon=True),
        ]
        for thread in self._threads:
            thread.start()

    def _write(self) -> None:
        seq = 0
        next_at = time.monotonic()
        while not self._ended.is_set():
            seq += 1
            self.written[seq] = time.monotonic()
            os.write(self.master, f"{{A{seq}:0:0:0}}$".encode())
            next_at += SLOT
            time.sleep(max(0.0, next_at - time.monotonic()))

    def _read(self) -> None:
        while not self._ended.is_set():
            try:
                data = os.read(self.master, 256)
            except OSError:
                return
            now = time.monotonic()
            self.letters += [now for byte in data if byte in LETTERS]

    def close(self) -> None:
        self._ended.set()
        os.close(self.master)
        os.close(self._slave)


# ---------------------------------------------------------------- the host: a client process


def client(url: str, keys: int) -> None:
    """`python -m bench.network client URL KEYS`: a host on URL sends KEYS letters at
    random moments, printing when it sent each (`k T`) and when it decoded each record
    (`r SEQ T`), as JSON lines."""
    import appmode  # noqa: F401 - registers the URL schemes
    from appmode.host.app.client import Host
    from appmode.protocol import app

    rng = random.Random(1)
    with Host(url) as host:
        end = time.monotonic() + 10
        while not any(isinstance(e, app.Velocity) for e in host.poll(0.1)):
            if time.monotonic() > end:
                raise SystemExit("no records from the car in 10 s")
        for k in range(keys):
            until = time.monotonic() + rng.uniform(0.02, 0.06)
            while time.monotonic() < until:
                for event in host.poll(0.002):
                    if isinstance(event, app.Velocity):
                        print(json.dumps(["r", event.x, time.monotonic()]))
            print(json.dumps(["k", time.monotonic()]), flush=True)
            host.send(LETTERS[k % len(LETTERS) : k % len(LETTERS) + 1])
        time.sleep(0.2)


def measured(command: list[str], car: Car) -> tuple[list[float], list[float]]:
    """Run the client `command`; its keys' delays to the car (s) and the records'
    delays from the car (s)."""
    before = len(car.letters)
    done = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
    if done.returncode != 0:
        raise SystemExit(f"the client failed: {done.stderr.strip()[-400:]}")
    lines = [json.loads(line) for line in done.stdout.splitlines()]
    sent = [line[1] for line in lines if line[0] == "k"]
    arrived = car.letters[before : before + len(sent)]
    keys = [a - s for s, a in zip(sent, arrived, strict=False)]
    records = [line[2] - car.written[line[1]] for line in lines if line[0] == "r"]
    return keys, records


def _client_command(machine: Machine | None, url: str, keys: int) -> list[str]:
    command = [sys.executable, "-m", "bench.network", "client", url, str(keys)]
    return command if machine is None else machine.command(*command)


@contextmanager
def _started(machine: Machine, *args: str) -> Iterator[subprocess.Popen[str]]:
    """`args` running on `machine` until the block ends, its first line read."""
    proc = subprocess.Popen(
        machine.command(*args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        if not line:
            raise SystemExit(f"{args[2:4]} did not start: {proc.communicate(timeout=10)[1]}")
        yield proc
    finally:
        proc.terminate()
        proc.wait(15)


def _ms(values: list[float], q: float) -> float:
    return percentile(values, q) * 1000


def bench_latency(keys: int) -> list[Row]:
    rows: list[Row] = []
    car = Car()
    try:
        with lan("car", "laptop") as machines:
            local_keys, local_records = measured(_client_command(None, car.path, keys), car)
            share = [sys.executable, "-m", "appmode", "share", car.path, "--name", "bench"]
            share += ["--listen", "tcp/0.0.0.0:7450", "--key", KEY]
            with _started(machines["car"], *share) as proc:
                assert proc.stdout is not None
                url = f"zenoh://bench?connect=tcp/{machines['car'].address}:7450&key=bench%20key"
                remote = measured(_client_command(machines["laptop"], url, keys), car)
        for what, local, far in (
            ("key-to-byte", local_keys, remote[0]),
            ("telemetry delay", local_records, remote[1]),
        ):
            over = _ms(far, 99) - _ms(local, 99)
            rows.append(
                Row(
                    f"network: {what}, shared over a veth pair vs local",
                    f"remote median {_ms(far, 50):.2f} ms, p99 {_ms(far, 99):.2f} ms; local "
                    f"median {_ms(local, 50):.2f} ms, p99 {_ms(local, 99):.2f} ms; "
                    f"overhead p99 {over:+.2f} ms (n={len(far)})",
                    "overhead p99 < 10 ms",
                    over < 10,
                )
            )
    finally:
        car.close()
    return rows


def bench_cpu(seconds: float) -> list[Row]:
    cars = 10
    with lan("car", "laptop") as machines:
        many = [sys.executable, "-m", "tests.support.many_cars", str(cars), "tcp/0.0.0.0:7450", KEY]
        with _started(machines["car"], *many) as proc:
            time.sleep(2)
            idle = cpu_share(proc.pid, seconds)
            url = f"zenoh://car-01?connect=tcp/{machines['car'].address}:7450&key=bench%20key"
            monitor = machines["laptop"].command(
                sys.executable, "-m", "appmode", "monitor", url, "--json"
            )
            with subprocess.Popen(monitor, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE):
                time.sleep(3)
                watched = cpu_share(proc.pid, seconds)
                subprocess.run(["pkill", "-f", "appmode monitor zenoh://car-01"], check=False)
    per_car = idle / cars
    return [
        Row(
            f"network: the sharing host's CPU per car ({cars} simulated cars, one process, "
            "their boards' model included)",
            f"{per_car:.2f} % of a core a car idle; {watched - idle:+.2f} % with a client "
            "watching one",
            "< 5 % a car",
            per_car < 5,
        )
    ]


def bench_fleet(cars: int) -> list[Row]:
    with lan("car", "laptop") as machines:
        many = [sys.executable, "-m", "tests.support.many_cars", str(cars), "tcp/0.0.0.0:7450", KEY]
        with _started(machines["car"], *many):
            time.sleep(2)
            start = time.monotonic()
            listed = machines["laptop"].run("fleet", "--key", KEY, "--json")
            took = time.monotonic() - start
    found = json.loads(listed.stdout or "[]")
    latency = sorted(car["latency_ms"] for car in found)
    return [
        Row(
            f"network: {cars} cars into one fleet view (appmode fleet --json, by scouting)",
            f"{len(found)} listed in {took:.2f} s (the process's start included); the "
            f"last car answered in {latency[-1] if latency else float('nan'):.1f} ms",
            f"all {cars} in < 5 s",
            len(found) == cars and took < 5,
        )
    ]


def bench_network(quick: bool) -> list[Row]:
    """Every row; one saying why where network namespaces cannot be made."""
    why = why_not()
    if why is not None:
        return [Row("network (Zenoh over veth)", f"not run: {why}", "", None)]
    return [
        *bench_latency(100 if quick else 400),
        *bench_cpu(5 if quick else 15),
        *bench_fleet(50),
    ]


def main() -> None:
    if sys.argv[1:2] == ["client"]:
        client(sys.argv[2], int(sys.argv[3]))
        return
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    for row in bench_network(args.quick):
        print(f"{row.benchmark}: {row.result} (target {row.target}: {row.met})")


if __name__ == "__main__":
    main()
