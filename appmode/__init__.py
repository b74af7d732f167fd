"""appmode: host, mock board and transcripts for the robot-car serial protocols.

The public API (docs/api.md):

- `Board`: the simulated board, a state machine with an injected clock;
- `HostDecoder`, `BoardDecoder` and `encode`: the APP codec, with no I/O;
- `Host`: the host side over any URL; `ControlHost`: the same over the control port;
- `open_link`: open a board by URL (importing appmode registers `sim://` with pyserial,
  so `serial.serial_for_url("sim://")` opens the simulated board in any program);
- `read_transcript`, `parse_transcript` and `Recorder`: the transcript reader and writer.
"""

from appmode.board.firmware import Board
from appmode.host.client import Host
from appmode.host.control_client import ControlHost
from appmode.ports.link import open_link
from appmode.protocol.app import BoardDecoder, HostDecoder, encode
from appmode.protocol.transcript import Recorder, parse_transcript, read_transcript

__version__ = "0.1.0"

__all__ = [
    "Board",
    "BoardDecoder",
    "ControlHost",
    "Host",
    "HostDecoder",
    "Recorder",
    "__version__",
    "encode",
    "open_link",
    "parse_transcript",
    "read_transcript",
]
