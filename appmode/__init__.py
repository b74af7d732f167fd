"""appmode: host, mock board and transcripts for the robot-car serial protocols.

The public API (docs/api.md):

- `Board`: the simulated board, a state machine with an injected clock;
- `HostDecoder`, `BoardDecoder` and `encode`: the APP codec, with no I/O;
- `Host`: the host side over any URL; `ControlHost`: the same over the control port;
- `open_link`: open a board by URL or `Target` (importing appmode registers `sim://`,
  `ble://` and `bt://` with pyserial, so `serial.serial_for_url("sim://")` opens the
  simulated board in any program); `parse_target`: a URL parsed once into a `Target`;
- `read_transcript`, `parse_transcript`, `Recorder` and `open_recorder`: the transcript
  reader and writer (to a stream, or to a file it opens);
- `AppmodeError` (what went wrong, where, how to fix it) and its `TranscriptError`.

Each name is imported when first used, so `import appmode` (and the pytest plugin that
pytest loads wherever appmode is installed) costs only pyserial's import; the `appmode`
program imports pyserial only for a command that opens a port (`ports.urls` registers
the URLs then), so that its start-up stays within that of pyserial's own miniterm.
"""

from __future__ import annotations

import importlib
import sys

from appmode.errors import AppmodeError


def register_urls() -> None:
    """Have pyserial open appmode's URLs (`serial.serial_for_url("sim://")`): sim://,
    ble://, bt:// and zenoh://, from the packages the scheme table names."""
    import serial

    from appmode.ports.schemes import handler_packages

    for package in handler_packages():
        if package not in serial.protocol_handler_packages:
            serial.protocol_handler_packages.append(package)


def _started_as_program() -> bool:
    """This interpreter runs `appmode` or `python -m appmode` (not a program that imports
    appmode)."""
    argv = getattr(sys, "argv", None) or [""]  # an embedding interpreter may have none
    if argv[0] == "-m":  # `python -m NAME` while NAME's package loads
        return sys.orig_argv[sys.orig_argv.index("-m") + 1 :][:1] == ["appmode"]
    return argv[0].replace("\\", "/").rsplit("/", 1)[-1] in ("appmode", "appmode.exe")


def _quit(signum: int, frame: object) -> None:
    raise SystemExit(130)


def quit_while_loading() -> None:
    """Ctrl-C ends the program quietly (exit 130, no traceback) until the command's own
    handling takes over (`cli.entry`)."""
    import signal

    signal.signal(signal.SIGINT, _quit)


if _started_as_program():
    quit_while_loading()  # first, before anything else of appmode loads
else:
    register_urls()

TYPE_CHECKING = False
"""typing.TYPE_CHECKING, without importing typing here (start-up: mypy reads the name)."""
if TYPE_CHECKING:
    from typing import Any

    from appmode.board.firmware import Board
    from appmode.host.app.client import Host
    from appmode.host.control.client import ControlHost
    from appmode.ports.recording import open_recorder
    from appmode.ports.target import Target, parse_target
    from appmode.ports.urls import open_link
    from appmode.protocol.app import encode
    from appmode.protocol.app_decoders import BoardDecoder, HostDecoder
    from appmode.protocol.recorder import Recorder
    from appmode.protocol.transcript import TranscriptError, parse_transcript
    from appmode.transcript.reading import read_transcript

__version__ = "0.1.0"

_WHERE = {
    "Board": "appmode.board.firmware",
    "Host": "appmode.host.app.client",
    "ControlHost": "appmode.host.control.client",
    "open_link": "appmode.ports.urls",
    "open_recorder": "appmode.ports.recording",
    "Target": "appmode.ports.target",
    "parse_target": "appmode.ports.target",
    "BoardDecoder": "appmode.protocol.app_decoders",
    "HostDecoder": "appmode.protocol.app_decoders",
    "encode": "appmode.protocol.app",
    "Recorder": "appmode.protocol.recorder",
    "TranscriptError": "appmode.protocol.transcript",
    "parse_transcript": "appmode.protocol.transcript",
    "read_transcript": "appmode.transcript.reading",
}


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module 'appmode' has no attribute {name!r}")
    value = getattr(importlib.import_module(_WHERE[name]), name)
    globals()[name] = value
    return value


__all__ = [
    "AppmodeError",
    "Board",
    "BoardDecoder",
    "ControlHost",
    "Host",
    "HostDecoder",
    "Recorder",
    "Target",
    "TranscriptError",
    "__version__",
    "encode",
    "open_link",
    "open_recorder",
    "parse_target",
    "parse_transcript",
    "read_transcript",
]
