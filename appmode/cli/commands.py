"""The commands, in the order `appmode --help` lists them, with their one-line help: the
command line loads a command's module (`appmode.cli.NAME`) only to run it."""

from __future__ import annotations

COMMANDS: dict[str, str] = {
    "drive": "drive and tune a car from the keyboard (the main job)",
    "web": "drive and tune a car from a browser: the page appmode serves",
    "demo": "drive the embedded simulated board through a short route, printing every record",
    "decode": "decode a raw byte stream to JSON Lines",
    "board": "serve the simulated board on a pseudo-terminal, TCP or a serial port",
    "send": "send letters and frames to a board and print what comes back",
    "params": "read, set (verified) and save the nine parameters",
    "monitor": "print decoded records as they arrive",
    "record": "log what a board sends to a transcript (passive)",
    "conform": "run transcripts as conformance tests against a board",
    "replay": "play one side of a transcript to a port",
    "tap": "sit between an app and a board, recording both directions",
    "dump": "decode a transcript",
    "plot": "draw a transcript's telemetry (needs matplotlib)",
    "ports": "list serial ports (USB-UART adapters, Bluetooth rfcomm)",
    "doctor": "find the car: check each serial port and say how to drive it or what to fix",
}
"""Each command's one-line help; its module has `register(sub)` (its arguments) and
`run(args)` (the job)."""
