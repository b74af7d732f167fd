"""A plain pyserial client of both ports of a board: python examples/uart2_pyserial.py APP UART2

Read max_speed over UART2, drive with a velocity frame and watch the APP port's A record
follow, find that after the take-over the APP letters no longer drive, then stop.
"""

from __future__ import annotations

import sys
import time

import serial

app_port, control_port = sys.argv[1], sys.argv[2]
uart3 = serial.Serial(app_port, 9600, timeout=1)
uart2 = serial.Serial(control_port, 115200, timeout=1)
uart2.write(bytes.fromhex("FF FE 80 80 11 00 00 00 00 00"))  # read max_speed
print("reply:", uart2.read(6).hex(" ").upper())
uart2.write(bytes.fromhex("FF FE 01 00 00 01 2C 00 00 00"))  # velocity y = 300
time.sleep(1)
uart3.reset_input_buffer()
uart3.read_until(b"$")  # the rest of a record
print("APP port:", uart3.read_until(b"$").decode(), uart3.read_until(b"$").decode())
uart3.write(b"JA")  # UART2 has taken over: the letters do nothing
uart2.write(bytes.fromhex("FF FE 01 00 00 00 00 00 00 00"))  # stop
time.sleep(1)
uart3.reset_input_buffer()
uart3.read_until(b"$")
print("APP port:", uart3.read_until(b"$").decode(), uart3.read_until(b"$").decode())
