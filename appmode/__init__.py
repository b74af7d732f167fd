"""appmode: host, mock board and transcripts for the robot-car APP serial protocol.

Importing appmode registers `sim://` with pyserial, so `serial.serial_for_url("sim://")`
opens the simulated board in any program that imports appmode.
"""

import serial

__version__ = "0.1.0"

if "appmode.urlhandler" not in serial.protocol_handler_packages:
    serial.protocol_handler_packages.append("appmode.urlhandler")
