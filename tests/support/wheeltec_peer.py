"""Both ends of a WHEELTEC chassis port written from ../shared/wheeltec-chassis.md alone,
with nothing of appmode: the vendor ROS driver's serial side (`VendorDriver`: R2's
`Get_Sensor_Data_New`, a byte at a time) and a simulated STM32 (`Stm32`: F1's command
handling, velocities applied at once). Tests hold appmode's board and host against them."""

from __future__ import annotations

import contextlib
import os
import select
import struct
import threading
import time
from dataclasses import dataclass, field

HEAD, TAIL = 0x7B, 0x7D
ACCEL_SCALE = 1671.84  # raw counts per m/s²
GYRO_SCALE = 0.00026644  # rad/s per raw count


def check_sum(data: bytes) -> int:
    value = 0
    for byte in data:
        value ^= byte
    return value


@dataclass
class Reading:
    """A status frame as the driver converts it (R1, R2)."""

    at: float
    flag_stop: int
    vx: float
    vy: float
    wz: float
    accel: tuple[float, float, float]
    gyro: tuple[float, float, float]
    volts: float


@dataclass
class VendorDriver:
    """The driver's serial side over a file descriptor: frames found as R2 does (start at
    0x7B, take 24 bytes, accept when byte 23 is 0x7D and byte 22 the XOR of 0–21, else
    start again), converted as it does; commands built as it builds them."""

    fd: int
    readings: list[Reading] = field(default_factory=list)
    rejected: int = 0
    _buffer: bytearray = field(default_factory=bytearray)

    def read_for(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            ready, _, _ = select.select([self.fd], [], [], left)
            if ready:
                for byte in os.read(self.fd, 4096):
                    self._byte(byte)

    def _byte(self, byte: int) -> None:
        if not self._buffer and byte != HEAD:
            return
        self._buffer.append(byte)
        if len(self._buffer) < 24:
            return
        frame, self._buffer = bytes(self._buffer), bytearray()
        if frame[23] != TAIL or check_sum(frame[:22]) != frame[22]:
            self.rejected += 1
            return
        numbers = struct.unpack(">hhhhhhhhhh", frame[2:22])
        self.readings.append(
            Reading(
                time.monotonic(),
                frame[1],
                numbers[0] / 1000,
                numbers[1] / 1000,
                numbers[2] / 1000,
                (numbers[3] / ACCEL_SCALE, numbers[4] / ACCEL_SCALE, numbers[5] / ACCEL_SCALE),
                (numbers[6] * GYRO_SCALE, numbers[7] * GYRO_SCALE, numbers[8] * GYRO_SCALE),
                numbers[9] / 1000,
            )
        )

    def send(self, vx: float, vy: float, wz: float) -> None:
        """A command frame as the driver builds it (truncating ×1000 to int16)."""
        body = bytes([HEAD, 0, 0]) + struct.pack(
            ">hhh", int(vx * 1000), int(vy * 1000), int(wz * 1000)
        )
        os.write(self.fd, body + bytes([check_sum(body), TAIL]))


class Stm32(threading.Thread):
    """A simulated WHEELTEC board on a file descriptor: takes 11-byte frames (a frame
    starts at 0x7B; one with a wrong tail or XOR is dropped), applies each velocity at
    once, and sends a status frame every 50 ms with that velocity, gravity on z and
    12.0 V; every frame taken is kept, in order."""

    def __init__(self, fd: int) -> None:
        super().__init__(daemon=True)
        self.fd = fd
        os.set_blocking(fd, False)  # a port no one reads yet must not hold the board up
        self.taken: list[tuple[float, float, float]] = []
        self.dropped = 0
        self.stalled = False
        """Set: no more status frames (a board whose send task hangs), frames still taken."""
        self._velocity = (0, 0, 0)
        self._buffer = bytearray()
        self._done = threading.Event()

    def run(self) -> None:
        next_status = time.monotonic()
        while not self._done.is_set():
            ready, _, _ = select.select([self.fd], [], [], max(0.0, next_status - time.monotonic()))
            if ready:
                try:
                    data = os.read(self.fd, 4096)
                except OSError:  # BlockingIOError among them
                    data = b""
                for byte in data:
                    self._byte(byte)
            if time.monotonic() >= next_status:
                next_status += 0.05
                if not self.stalled:
                    self._status()

    def _byte(self, byte: int) -> None:
        if not self._buffer and byte != HEAD:
            return
        self._buffer.append(byte)
        if len(self._buffer) < 11:
            return
        frame, self._buffer = bytes(self._buffer), bytearray()
        if frame[10] != TAIL or check_sum(frame[:9]) != frame[9]:
            self.dropped += 1
            return
        vx, vy, wz = struct.unpack(">hhh", frame[3:9])
        self._velocity = (vx, vy, wz)
        self.taken.append((vx / 1000, vy / 1000, wz / 1000))

    def _status(self) -> None:
        vx, vy, wz = self._velocity
        gyro_z = round(wz / 1000 / GYRO_SCALE)
        body = bytes([HEAD, 0]) + struct.pack(
            ">hhhhhhhhhh", vx, vy, wz, 0, 0, round(9.8 * ACCEL_SCALE), 0, 0, gyro_z, 12000
        )
        with contextlib.suppress(OSError):  # no one reads the port yet
            os.write(self.fd, body + bytes([check_sum(body), TAIL]))

    def stop(self) -> None:
        """Stops the board, having taken every frame already written to it (the loop may
        end between a host's last write and its next read)."""
        self._done.set()
        self.join(2)
        while True:
            try:
                data = os.read(self.fd, 4096)
            except OSError:  # BlockingIOError: nothing left
                return
            if not data:
                return
            for byte in data:
                self._byte(byte)
