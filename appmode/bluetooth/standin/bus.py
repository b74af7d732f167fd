"""A private D-Bus bus: Debian's `dbus-daemon` with a configuration of our own, listening
on a socket in a new folder, so the BlueZ stand-in never touches the machine's system bus.
Programs reach it with DBUS_SYSTEM_BUS_ADDRESS set to `address`.

The daemon dies with us, however we end (SIGKILL too): it runs under a watcher shell
that waits for the end of a pipe only we hold, then stops it; the shell stops it too
when it is told to end (a hangup to the process group: dbus-daemon takes SIGHUP for
"reload" and would outlive it), and the daemon gets SIGTERM when the shell dies however
it dies (util-linux's `setpriv --pdeathsig`, where the machine has it). A folder left by
a bus whose owner is gone (a machine's power cut) is removed by the next bus started."""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import tempfile
import threading
from pathlib import Path
from types import TracebackType

from appmode.errors import AppmodeError

CONFIG = """<!DOCTYPE busconfig PUBLIC "-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN"
 "http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd">
<busconfig>
  <type>appmode</type>
  <listen>unix:path={socket}</listen>
  <auth>EXTERNAL</auth>
  <policy context="default">
    <allow user="*"/>
    <allow own="*"/>
    <allow send_destination="*" eavesdrop="true"/>
    <allow receive_sender="*"/>
  </policy>
  <limit name="max_message_unix_fds">16</limit>
</busconfig>
"""
"""Anyone on this machine who can reach the socket (a folder only its owner may enter)
may own a name and call anything: the bus carries one stand-in and its clients."""
WATCHER = """
"$0" "$@" & daemon=$!
trap 'kill "$daemon" 2>/dev/null; exit 1' HUP INT TERM
read -r _
kill "$daemon" 2>/dev/null
wait "$daemon"
"""
"""Runs the daemon (its stdin /dev/null) and stops it once our end of its stdin pipe is
closed (by `close`, or by the kernel when we die) or the shell is told to end."""
PREFIX = "appmode-bus-"
OWNER = "owner"
"""The file in a bus's folder that holds the process id of the program that made it."""
START = 5.0
"""Seconds the daemon may take to say its address."""
NO_DAEMON = (
    "dbus-daemon is not installed: the BlueZ stand-in runs its own D-Bus bus with it "
    "(Debian, Ubuntu: sudo apt install dbus-daemon; Fedora: sudo dnf install dbus-daemon)"
)


class PrivateBus:
    """A `dbus-daemon` of our own, stopped (and its folder removed) by `close`."""

    def __init__(self) -> None:
        daemon = shutil.which("dbus-daemon")
        if daemon is None:
            raise AppmodeError(NO_DAEMON)
        _remove_stale()
        self._folder = Path(tempfile.mkdtemp(prefix=PREFIX))
        (self._folder / OWNER).write_text(str(os.getpid()), encoding="ascii")
        config = self._folder / "bus.conf"
        config.write_text(CONFIG.format(socket=self._folder / "bus"), encoding="utf-8")
        arguments = [f"--config-file={config}", "--nofork", "--nopidfile", "--print-address"]
        setpriv = shutil.which("setpriv")  # the daemon dies with the shell, SIGKILL too
        command = [setpriv, "--pdeathsig", "TERM", daemon] if setpriv else [daemon]
        self._process = subprocess.Popen(
            ["/bin/sh", "-c", WATCHER, *command, *arguments],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            self.address = self._read_address()
        except BaseException:
            self.close()
            raise

    def _read_address(self) -> str:
        try:
            line = _first_line(self._process, START)
        except subprocess.TimeoutExpired:
            raise AppmodeError(f"dbus-daemon did not start within {START:g} s") from None
        if not line.startswith("unix:"):
            why = (self._process.stderr.read() if self._process.stderr else "").strip()
            raise AppmodeError(f"dbus-daemon did not start: {why or 'no address printed'}")
        return line.strip()

    def close(self) -> None:
        if self._process.stdin is not None:
            with contextlib.suppress(OSError):
                self._process.stdin.close()  # the watcher stops the daemon
        try:
            self._process.wait(2)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
        for stream in (self._process.stdout, self._process.stderr):
            if stream is not None:
                stream.close()
        shutil.rmtree(self._folder, ignore_errors=True)

    def __enter__(self) -> PrivateBus:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


def _first_line(process: subprocess.Popen[str], timeout: float) -> str:
    """The first line the daemon prints (its address), waiting at most `timeout`."""
    got: list[str] = []
    reader = threading.Thread(
        target=lambda: got.append(process.stdout.readline() if process.stdout else ""),
        daemon=True,
    )
    reader.start()
    reader.join(timeout)
    if reader.is_alive():
        raise subprocess.TimeoutExpired("dbus-daemon", timeout)
    return got[0] if got else ""


def _remove_stale() -> None:
    """Remove the bus folders of ours whose owner is no longer running."""
    for folder in Path(tempfile.gettempdir()).glob(f"{PREFIX}*"):
        try:
            if folder.lstat().st_uid != os.getuid() or not folder.is_dir():
                continue
            owner = int((folder / OWNER).read_text(encoding="ascii"))
        except (OSError, ValueError):
            continue  # not ours, or being made right now
        if not _running(owner):
            shutil.rmtree(folder, ignore_errors=True)


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
