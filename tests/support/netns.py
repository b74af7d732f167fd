"""Machines on a LAN for the network's tests: Linux network namespaces (the car's host, a
laptop, a stranger) joined by veth pairs to a bridge in a namespace of their own. Every
packet stays inside them: Zenoh's scouting (multicast) runs on their interfaces only,
never on the machine's own. Needs root (or CAP_NET_ADMIN) and iproute2's `ip`: where
they are missing, `lan()` says why, for a test to skip with."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from tests.support.processes import ROOT

SUBNET = "10.77.{}.{}"


@dataclass
class Machine:
    """A namespace standing for a machine: its name, its address on the LAN."""

    netns: str
    address: str
    device: str

    def command(self, *args: str) -> list[str]:
        """`args` run inside this machine."""
        return ["ip", "netns", "exec", self.netns, *args]

    def appmode(self, *args: str) -> list[str]:
        return self.command(sys.executable, "-m", "appmode", *args)

    def popen(self, *args: str, **kwargs: object) -> subprocess.Popen[str]:
        """`appmode ARGS` running on this machine."""
        return subprocess.Popen(  # type: ignore[call-overload, no-any-return]
            self.appmode(*args),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
            **kwargs,
        )

    def run(
        self, *args: str, stdin: str = "", timeout: float = 60
    ) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            self.appmode(*args),
            input=stdin,
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=ROOT,
            check=False,
        )

    def cut(self) -> None:
        """The machine's network cable pulled."""
        subprocess.run(["ip", "-n", self.netns, "link", "set", self.device, "down"], check=True)


def why_not() -> str | None:
    """Why namespaces cannot be made here, or None."""
    if shutil.which("ip") is None:
        return "iproute2's ip is not installed (apt install iproute2)"
    if hasattr(os, "geteuid") and os.geteuid() != 0:
        return "making network namespaces needs root"
    probe = f"amprobe{os.getpid()}"
    made = subprocess.run(["ip", "netns", "add", probe], capture_output=True, text=True)
    if made.returncode != 0:
        return f"ip netns add failed: {made.stderr.strip()}"
    subprocess.run(["ip", "netns", "del", probe], capture_output=True)
    return None


@contextmanager
def lan(*names: str) -> Iterator[dict[str, Machine]]:
    """Machines called `names` on one LAN (10.77.N.x/24), torn down after."""
    tag = f"am{os.getpid() % 100000}"
    net = (os.getpid() % 200) + 20
    bridge = f"{tag}-lan"
    made = [bridge]
    machines: dict[str, Machine] = {}

    def ip(*args: str) -> None:
        subprocess.run(["ip", *args], check=True, capture_output=True)

    try:
        ip("netns", "add", bridge)
        ip("-n", bridge, "link", "add", "br0", "type", "bridge")
        ip("-n", bridge, "link", "set", "br0", "up")
        for n, name in enumerate(names, start=2):
            netns = f"{tag}-{name}"
            ip("netns", "add", netns)
            made.append(netns)
            ip(
                "-n",
                netns,
                "link",
                "add",
                "eth0",
                "type",
                "veth",
                "peer",
                "name",
                f"to{n}",
                "netns",
                bridge,
            )
            ip("-n", bridge, "link", "set", f"to{n}", "master", "br0")
            ip("-n", bridge, "link", "set", f"to{n}", "up")
            address = SUBNET.format(net, n)
            ip("-n", netns, "addr", "add", f"{address}/24", "dev", "eth0")
            ip("-n", netns, "link", "set", "eth0", "up")
            ip("-n", netns, "link", "set", "lo", "up")
            machines[name] = Machine(netns, address, "eth0")
        yield machines
    finally:
        for netns in reversed(made):
            subprocess.run(["ip", "netns", "del", netns], capture_output=True)
