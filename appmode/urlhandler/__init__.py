"""pyserial URL handlers: `serial.serial_for_url("sim://")` once appmode is imported."""
