"""Real I/O: open anything by URL, `sim://` as a pyserial port, and serving boards on
pseudo-terminals, TCP and serial ports. Uses the layers below.

pyserial finds `sim://` here: `appmode.ports.urls` adds this package to
`serial.protocol_handler_packages`, and `protocol_sim` names the port class.
"""
