"""appmode: host, mock board and transcripts for the robot-car APP serial protocol."""

__version__ = "0.1.0"
