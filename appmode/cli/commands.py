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
    "convert": "convert a transcript to MCAP (for Foxglove) and back, losslessly",
    "ports": "list serial ports (USB-UART adapters, Bluetooth rfcomm)",
    "scan": "list nearby Bluetooth modules (BLE and paired classic) and their URLs",
    "doctor": "find the car: check each serial port and say how to drive it or what to fix",
    "share": "put a car on the network (Zenoh) for other machines to drive, watch and record",
    "fleet": "list the cars shared on the network that a key opens; fleet stop stops them",
    "router": "run a Zenoh router in-process, for shares and clients on other networks",
    "ros": "run the car as a ROS 2 node (rmw_zenoh's wire; no ROS installed here)",
    "protocol": "print the protocol reference, or one of its sections",
    "profile": "list the firmware profiles, show one, check your own profile file",
    "completion": "print the shell's completion script (bash, zsh, fish)",
}
"""Each command's one-line help; its module has `register(sub)` (its arguments) and
`run(args)` (the job)."""

EXAMPLES: dict[str, tuple[str, ...]] = {
    "drive": (
        "appmode drive",
        "appmode drive /dev/ttyUSB0 --profile minibalance",
        "printf 'drive A\\nwait 1\\n' | appmode drive",
    ),
    "web": ("appmode web", "appmode web /dev/rfcomm0 --listen 0.0.0.0:8080"),
    "demo": ("appmode demo", "appmode demo --profile minibalance"),
    "decode": ("appmode decode capture.bin", "appmode decode --from host < sent.bin"),
    "board": (
        "appmode board --pty",
        "appmode board --listen 5000 --profile minibalance",
        "appmode board --advertise HC-08",
    ),
    "send": ("appmode send sim:// J A wait:1", "appmode send /dev/ttyUSB0 '{Q:P}' --json"),
    "params": (
        "appmode params sim://",
        "appmode params /dev/ttyUSB0 --set max_speed=800 --save",
        "appmode params ble://HC-08",
    ),
    "monitor": ("appmode monitor sim:// --count 4", "appmode monitor /dev/ttyUSB0 --json"),
    "record": ("appmode record /dev/ttyUSB0 car.transcript --duration 60",),
    "conform": ("appmode conform", "appmode conform --board /dev/ttyUSB0 --yes"),
    "replay": (
        "appmode replay car.transcript --to /dev/ttyUSB0",
        "appmode replay car.transcript --to pty --side board",
    ),
    "profile": (
        "appmode profile list",
        "appmode profile show balance",
        "appmode profile check my-car.toml",
    ),
    "tap": (
        "appmode tap pty /dev/ttyUSB0 --record app.transcript",
        "appmode tap advertise:HC-08 ble://AA:BB:CC:DD:EE:FF --record phone.transcript",
    ),
    "dump": ("appmode dump car.transcript", "appmode dump car.transcript --csv > car.csv"),
    "plot": ("appmode plot car.transcript -o car.png",),
    "convert": (
        "appmode convert car.transcript car.mcap",
        "appmode convert car.mcap car.transcript",
    ),
    "ports": ("appmode ports",),
    "scan": ("appmode scan", "appmode scan --time 10 --json"),
    "doctor": ("appmode doctor", "appmode doctor /dev/ttyUSB0 --json"),
    "share": (
        "appmode share sim:// --name car",
        "appmode share /dev/ttyUSB0 --name car-1 --listen tcp/0.0.0.0:7450",
    ),
    "fleet": ("appmode fleet", "appmode fleet --json", "appmode fleet stop"),
    "router": ("appmode router --listen tcp/0.0.0.0:7447",),
    "ros": (
        "appmode ros sim:// --router",
        "appmode ros /dev/ttyUSB0 /dev/ttyAMA0 --namespace robot1",
    ),
    "protocol": ("appmode protocol", "appmode protocol 8.3", "appmode protocol II"),
    "completion": (
        "appmode completion bash > ~/.local/share/bash-completion/completions/appmode",
        "appmode completion fish > ~/.config/fish/completions/appmode.fish",
    ),
}
"""Two or three examples a command, shown at the end of its --help (each parses: a test
checks them)."""
