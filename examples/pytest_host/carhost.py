"""A small host for a MiniBalance/WHEELTEC robot car, written with pyserial alone.

It stands for the code appmode's users write themselves (a ROS node's serial layer, a
Raspberry Pi script) and test against appmode's simulated board: see test_carhost.py,
which uses the fixtures of appmode's pytest plugin and imports nothing of appmode.
"""

from __future__ import annotations

import re
import struct
import time

import serial

RECORD = re.compile(rb"\{([ABC])(-?\d+(?::-?\d+)*)\}\$")
"""An A, B or C record of the APP port: letter, then fields split by colons."""
STOP_FRAME = bytes.fromhex("FF FE 01 00 00 00 00 00 00 00")
"""The control port's counterpart of `Z`: a velocity frame of zeros."""


class AppPort:
    """The APP port (UART3, 9600 bps): letters drive, {…} frames set and read."""

    def __init__(self, url: str) -> None:
        self.serial = serial.serial_for_url(url, baudrate=9600, timeout=0.05)
        self._held = b""

    def forward(self) -> None:
        self.serial.write(b"JA")  # the direction page, then forward

    def stop(self) -> None:
        self.serial.write(b"Z")

    def set_param(self, index: int, value: int) -> None:
        self.serial.write(b"{%d:%d}" % (index, value))

    def save(self) -> None:
        self.serial.write(b"{Q:W}")

    def records(self, seconds: float) -> list[tuple[str, list[int]]]:
        """Every record that arrives in the next `seconds`."""
        found: list[tuple[str, list[int]]] = []
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self._held += self.serial.read(256)
            for match in RECORD.finditer(self._held):
                found.append((match[1].decode(), [int(f) for f in match[2].split(b":")]))
            self._held = self._held[self._held.rfind(b"$") + 1 :]
        return found

    def read_params(self, timeout: float = 2.0) -> list[int]:
        """Ask for the parameters ({Q:P}) and wait for the C record."""
        self.serial.write(b"{Q:P}")
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for letter, fields in self.records(0.1):
                if letter == "C":
                    return fields
        raise TimeoutError("no C record")

    def close(self) -> None:
        self.stop()
        self.serial.flush()
        self.serial.close()


class ControlPort:
    """The control port (UART2, 115200 bps): binary FF FE frames."""

    def __init__(self, url: str) -> None:
        self.serial = serial.serial_for_url(url, baudrate=115200, timeout=0.5)

    def velocity(self, x: int, y: int, z: int) -> None:
        """Mode 01 on an omni or mecanum car: magnitudes, then the sign bits X, Y, Z."""
        signs = (x < 0) << 2 | (y < 0) << 1 | (z < 0)
        body = struct.pack(">HHHB", abs(x), abs(y), abs(z), signs)
        self.serial.write(b"\xff\xfe\x01" + body)

    def read_setting(self, number: int) -> int:
        """Read setting 1–10 (max_speed … gyro_calibration): reply `23 NN` + u32."""
        self.serial.reset_input_buffer()
        self.serial.write(bytes([0xFF, 0xFE, 0x80, 0x80, 0x10 + number, 0, 0, 0, 0, 0]))
        end = time.monotonic() + 1.0
        held = b""
        while time.monotonic() < end:
            held += self.serial.read(1)
            at = held.find(bytes([0x23, number]))
            if at >= 0 and len(held) >= at + 6:
                (value,) = struct.unpack(">I", held[at + 2 : at + 6])
                return int(value)
        raise TimeoutError(f"no reply reading setting {number}")

    def set_setting(self, number: int, value: int) -> None:
        self.serial.write(
            bytes([0xFF, 0xFE, 0x80, 0x80, number]) + struct.pack(">I", value) + b"\0"
        )

    def encoder_report(self, on: bool) -> None:
        """system_mode (setting 9) bit 6: the board reports its wheels every 50 ms."""
        mode = self.read_setting(9)
        self.set_setting(9, mode | 0x40 if on else mode & ~0x40)

    def reports(self, seconds: float, wheels: int = 4) -> list[list[tuple[int, int]]]:
        """Encoder reports (`24`, target/actual per wheel, `19`) of the next `seconds`."""
        size = 2 + 8 * wheels
        found, held = [], b""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            held += self.serial.read(max(1, self.serial.in_waiting))
            while (at := held.find(b"\x24")) >= 0 and len(held) >= at + size:
                unit, held = held[at : at + size], held[at + size :]
                if unit[-1] == 0x19:
                    values = struct.unpack(f">{2 * wheels}i", unit[1:-1])
                    found.append(list(zip(values[::2], values[1::2], strict=True)))
        return found

    def close(self) -> None:
        self.serial.write(STOP_FRAME)
        self.serial.flush()
        self.serial.close()
